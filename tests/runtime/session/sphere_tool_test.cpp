// The sphere tool through the servo and the frame stage, the device held still until the object is at rest: the
// sphere rests one radius above the face it presses (less an indentation of Hertz's order) where a point tool's
// proxy sinks below the face, its force goes to the nodes under its contact patch, and Hertz indentation by the
// tool approaches the closed form as the level rises.
#include <gtest/gtest.h>

#include <cmath>

#include "core/scene.h"
#include "sim/contact/contact_model_error.h"
#include "tools/bench/bench_model.h"
#include "runtime/session/model.h"
#include "runtime/session/tool_hold.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

// A 6 cm cube of a stiff silicone (1 MPa), floor fixed; the top face at z = 3 cm.
std::string cube(const char* shape) {
  return std::string(R"({
  "mesh": {"box_m": [0.06, 0.06, 0.06], "box_subdivisions": 24, "size_m": 0.06},
  "grid": {"levels": 5},
  "lattice": {"level": 5, "radius_cells": 3, "fix_floor": true, "integrator": "local_global"},
  "material": {"young_modulus_Pa": 1e6, "poisson_ratio": 0.25, "density_kg_per_m3": 1070, "stiffness_damping_s": 0.01},
  "device": {"max_force_N": 20, "coupling_N_per_m": 300, "coupling_damping_Ns_per_m": 0, "tool_radius_m": 0.01,
             "tool_shape": ")") + shape + R"(", "workspace_half_m": 0.2},
  "interaction": {"mode": "touch"},
  "trajectory": [{"t_s": 0.0, "pos_m": [0.0, 0.0, 0.05]}]
})";
}

ToolHoldResult hold(const char* shape, const Vec3& device) {
  const Scene scene = parse_scene(cube(shape), "cube.json").value();
  const Model model = load_model(scene).value();
  ToolHoldOptions o;
  o.device_pos_m = device;
  o.start_pos_m = device + Vec3(0, 0, 0.02);  // from above the face
  o.approach_s = 0.3;
  auto r = hold_tool(scene, model, o);
  EXPECT_TRUE(r) << r.error().message;
  return r ? r.value() : ToolHoldResult{};
}

TEST(SphereToolHeld, RestsOneRadiusAboveTheFaceWhereAPointSinks) {
  // the device brought down to 3 mm under the top face, 0.25 mm from a cell boundary (cells of 3.75 mm at level 5)
  const double top = 0.03, radius = 0.01;
  const Vec3 device(0.0035, 0.001875, top - 0.003);
  const ToolHoldResult sphere = hold("sphere", device);
  const ToolHoldResult point = hold("point", device);
  ASSERT_TRUE(sphere.at_rest) << sphere.frames << " frames, speed " << sphere.max_node_speed_m_per_s;
  ASSERT_TRUE(point.at_rest) << point.frames << " frames, speed " << point.max_node_speed_m_per_s;
  const double sphere_sinks = top + radius - sphere.proxy_m.z();
  const double point_sinks = top - point.proxy_m.z();
  // the sphere: its centre one radius above the face, less its indentation, which is of the order of Hertz's
  // for its force (0.9 mm in a half-space; the floor 6 cm down and the lattice stiffen it)
  const double e_star = 1e6 / (1 - 0.0625);
  const double hertz_m = std::pow(3 * sphere.force_N.z() / (4 * e_star * std::sqrt(radius)), 2.0 / 3.0);
  EXPECT_GT(sphere_sinks, 0.2 * hertz_m) << "centre " << sphere.proxy_m.transpose();
  EXPECT_LT(sphere_sinks, 1.2 * hertz_m) << "centre " << sphere.proxy_m.transpose();
  EXPECT_LT(sphere_sinks, 0.1 * radius);
  EXPECT_NEAR(sphere.proxy_m.x(), device.x(), 1e-4);
  EXPECT_NEAR(sphere.proxy_m.y(), device.y(), 1e-4);
  // the coupling: k_c (centre - device), pushing the device up
  EXPECT_NEAR(sphere.force_N.z(), 300 * (sphere.proxy_m.z() - device.z()), 1e-2);
  // a point tool held at the same place has its proxy on the face, sunk below the rest top
  EXPECT_GT(point_sinks, 0.0);
  EXPECT_LT(point.proxy_m.z(), sphere.proxy_m.z() - 0.9 * radius);
  // the sphere's force went to the nodes of more than one cell (its contact patch crosses the cell boundary), the
  // point's to the 8 of the cell under it
  EXPECT_GT(sphere.force_nodes, 8);
  EXPECT_LE(point.force_nodes, 8);
}

// The bench's Hertz block material: 100 kPa, run to rest quickly.
MaterialSpec hertz_material() {
  MaterialSpec m = test::soft_material();
  m.stiffness_damping_s = 0.02;
  return m;
}

// Hertz indentation by the sphere tool (R = 10 cm, about 0.25 mm deep, contact radius 5 mm) on an 8 x 8 x 4 cm
// block run to rest: the force error falls from level 4 (contact radius half a cell) to level 5 (one cell), where
// it is within 15 % of 4/3 E* sqrt(R) d^(3/2).
TEST(SphereToolHeld, HertzIndentationByTheToolApproachesTheClosedForm) {
  const MaterialSpec m = hertz_material();
  auto coarse = check_hertz_tool(m, 4, IntegratorKind::kImplicitEuler);
  auto fine = check_hertz_tool(m, 5, IntegratorKind::kImplicitEuler);
  ASSERT_TRUE(coarse) << coarse.error().message;
  ASSERT_TRUE(fine) << fine.error().message;
  EXPECT_NEAR(fine.value().depth_m, 2.5e-4, 1e-4);
  EXPECT_LT(std::abs(fine.value().rel_error), std::abs(coarse.value().rel_error))
      << "level 4 " << coarse.value().rel_error << ", level 5 " << fine.value().rel_error;
  EXPECT_LT(std::abs(fine.value().rel_error), 0.15) << "F " << fine.value().force_N << " N, Hertz "
                                                    << fine.value().closed_form_N << " N";
  EXPECT_GT(fine.value().force_nodes, 8);
}

// The same block with the contact solved (device.contact "solved"): Hertz is only the check. At level 5 (contact
// radius one cell) the force the lattice carries for its surface's drop is within 10 % of Hertz's, and the push went
// where the contact put it on every frame but the first (the factor of the region's stiffness comes after the first
// contact), spread over more nodes than a point's (at most 8 on this block).
TEST(SphereToolHeld, WithTheContactSolvedHertzIsTheCheckNotTheLoad) {
  const MaterialSpec m = hertz_material();
  auto solved = check_hertz_tool(m, 5, IntegratorKind::kImplicitEuler, {}, true);
  ASSERT_TRUE(solved) << solved.error().message;
  const HertzToolCheck& h = solved.value();
  EXPECT_NEAR(h.depth_m, 2.5e-4, 1e-4);
  EXPECT_LT(std::abs(h.rel_error), 0.10) << "F " << h.force_N << " N, Hertz " << h.closed_form_N << " N";
  EXPECT_GE(h.solved_frames, h.frames - 3);
  EXPECT_GT(h.force_nodes, 8);  // a point load here goes to at most 8
}

// The model error summary.json states is read off two tables measured by `palpate bench model`; the tables are what
// the bench's own run gives now, prescribed and solved (level 4: the 5 mm contact radius is half a 10 mm cell), so
// a change of the contact's load that moves the figures fails here until the tables are measured again.
TEST(SphereToolHeld, TheContactModelErrorTablesAreWhatTheBenchMeasures) {
  const MaterialSpec m = hertz_material();
  for (bool solved : {false, true}) {
    auto run = check_hertz_tool(m, 4, IntegratorKind::kImplicitEuler, {}, solved);
    ASSERT_TRUE(run) << run.error().message;
    const ContactModelError table = contact_model_error(m, true, 0.005, 0.01, solved);
    ASSERT_TRUE(table.defined);
    EXPECT_DOUBLE_EQ(table.contact_radius_cells, 0.5);
    EXPECT_NEAR(table.hertz_force_error, run.value().rel_error, 0.02) << (solved ? "solved" : "prescribed");
  }
}

// The volumetric model below nu = 1/4 (the Neo-Hookean split, a fifth of mu in the springs) at nu 0 and level 5, the
// contact radius one cell: the tables hold what the bench measures (with a tenth in the springs the prescribed row was
// -40.6 %, the table's -26.1 %).
TEST(SphereToolHeld, TheVolumetricNuZeroRowsAreWhatTheBenchMeasures) {
  MaterialSpec m = hertz_material();
  m.model = MaterialModel::kVolumetric;
  m.poisson_ratio = 0.0;
  for (bool solved : {false, true}) {
    auto run = check_hertz_tool(m, 5, IntegratorKind::kImplicitEuler, {}, solved);
    ASSERT_TRUE(run) << run.error().message;
    const ContactModelError table = contact_model_error(m, true, 0.005, 0.005, solved);
    ASSERT_TRUE(table.defined);
    EXPECT_DOUBLE_EQ(table.contact_radius_cells, 1.0);
    EXPECT_NEAR(table.hertz_force_error, run.value().rel_error, 0.02) << (solved ? "solved" : "prescribed");
  }
}

}  // namespace
}  // namespace palpate
