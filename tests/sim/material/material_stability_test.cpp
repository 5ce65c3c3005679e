// The explicit schemes on material lattices: a scene whose material and level no capped substep count can hold is
// refused at load, and what is refused does diverge when run, what is accepted does not.
#include <gtest/gtest.h>

#include "sim/solvers/integrator.h"
#include "sim/reference/reference_cases.h"
#include "sim/solvers/stability.h"
#include "sim/sim_test_util.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

// The shipped silicone phantom's material with the model asked.
MaterialSpec phantom(double e_Pa, MaterialModel model) {
  MaterialSpec m = test::soft_material(0.45, model);
  m.young_modulus_Pa = e_Pa;
  m.stiffness_damping_s = 2e-3;
  return m;
}

LatticeSpec scheme(const MaterialSpec& m, IntegratorKind kind) {
  LatticeSpec spec;
  spec.material = m;
  spec.level = 5;
  spec.integrator = kind;
  spec.max_substeps = 256;
  return spec;
}

// Frames of dt at the scene's cap of 256 substeps after a small kick; whether the lattice stayed finite and bounded.
bool stays_bounded(const MaterialSpec& m, IntegratorKind kind, double dt_s) {
  Lattice lat = box_lattice(m, 0.06, 5, {4, 4, 4}).value();
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) lat.fixed[i] = lat.rest_m[i].z() < 1e-9;
  lat.touch();
  test::kick(&lat, 1e-6);
  const double e0 = test::energy_J(lat);
  StepOptions o = test::opts(kind);
  o.max_substeps = 256;
  IntegratorWorkspace ws;
  for (int frame = 0; frame < 20; ++frame) step_lattice(&lat, o, dt_s, {}, &ws);
  return test::all_finite(lat) && test::energy_J(lat) < 10.0 * e0;
}

TEST(MaterialStability, WhatIsRefusedAtLoadDivergesAndWhatIsAcceptedDoesNot) {
  const double dt_s = 1.0 / 60.0, cell_m = 0.06 / 16.0;  // box_lattice's cells at level 5
  for (MaterialModel model : {MaterialModel::kSprings, MaterialModel::kVolumetric, MaterialModel::kNeoHookean}) {
    SCOPED_TRACE(name_of(model));
    // the phantom's 300 kPa on 3.75 mm cells: far more than 256 substeps a frame
    const MaterialSpec stiff = phantom(3e5, model);
    const Status refused = check_material_integrator(scheme(stiff, IntegratorKind::kSymplecticEuler), cell_m, dt_s);
    ASSERT_FALSE(refused.ok());
    const std::string& msg = refused.error().message;
    EXPECT_NE(msg.find("lattice.integrator 'symplectic_euler' needs"), std::string::npos) << msg;
    EXPECT_NE(msg.find("lattice.max_substeps is 256"), std::string::npos) << msg;
    EXPECT_NE(msg.find("implicit_euler"), std::string::npos) << msg;
    EXPECT_FALSE(stays_bounded(stiff, IntegratorKind::kSymplecticEuler, dt_s));
    EXPECT_FALSE(check_material_integrator(scheme(stiff, IntegratorKind::kRk4), cell_m, dt_s).ok());
    EXPECT_FALSE(check_material_integrator(scheme(stiff, IntegratorKind::kExplicitEuler), cell_m, dt_s).ok());
    // the implicit schemes take any stiffness
    EXPECT_TRUE(check_material_integrator(scheme(stiff, IntegratorKind::kImplicitEuler), cell_m, dt_s).ok());
    // a hundred times softer fits in the cap, and runs so
    const MaterialSpec soft = phantom(3e3, model);
    EXPECT_TRUE(check_material_integrator(scheme(soft, IntegratorKind::kSymplecticEuler), cell_m, dt_s).ok());
    EXPECT_TRUE(stays_bounded(soft, IntegratorKind::kSymplecticEuler, dt_s));
  }
}

TEST(MaterialStability, TheLoadBoundIsTheLeastABuiltLatticeNeeds) {
  // the bound is taken at a full interior node; a built lattice's surface nodes carry less mass for their springs,
  // so its Gershgorin step is never longer than the check's, and the check refuses only what is sure to diverge
  for (double e_Pa : {1e3, 3e4, 3e5}) {
    const MaterialSpec m = phantom(e_Pa, MaterialModel::kVolumetric);
    Lattice lat = box_lattice(m, 0.06, 5, {4, 4, 4}).value();
    const double h_lattice = stability_bound(lat, 0.8).max_stable_dt_s;
    // the largest frame step the check accepts at one substep is its interior bound
    LatticeSpec spec = scheme(m, IntegratorKind::kSymplecticEuler);
    spec.substeps = 1;
    EXPECT_TRUE(check_material_integrator(spec, lat.cell_m, 0.999 * h_lattice).ok()) << e_Pa;
  }
}

}  // namespace
}  // namespace palpate
