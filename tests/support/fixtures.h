#pragma once
// Shared test fixtures: a box model filling its grid cube, tolerances, a soft material.

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/aabb.h"
#include "core/grid_hierarchy.h"
#include "core/mesh_io.h"
#include "core/scene.h"
#include "core/tri_mesh.h"
#include "support/temp_root.h"

namespace palpate::test {

inline constexpr double kTightTol = 1e-12;  ///< round-off level for unit-size geometry

/// A box mesh whose grid cube is the box itself, so every cell at every level is solid.
struct BoxModel {
  TriMesh mesh;
  GridHierarchy grid;
};

/// Builds a BoxModel of side side_m with `levels` grid levels.
inline BoxModel make_box_model(double side_m, int levels, int subdivisions = 8) {
  BoxModel b;
  b.mesh = make_box_mesh(Vec3::Constant(side_m), subdivisions);
  Aabb cube{Vec3::Constant(-side_m / 2), Vec3::Constant(side_m / 2)};
  b.grid = GridHierarchy::build(b.mesh, cube, levels).value();
  return b;
}

/// Lattice spec with only the given families on, gravity off.
inline LatticeSpec spec_for(int level, double ks, double kh, double kb) {
  LatticeSpec s;
  s.level = level;
  s.radius_cells = 64;
  s.node_mass_kg = 0.01;
  s.structural_N_per_m = ks;
  s.shear_N_per_m = kh;
  s.bend_N_per_m = kb;
  s.damping_Ns_per_m = 0.05;
  s.gravity_m_per_s2 = Vec3::Zero();
  return s;
}

/// A soft solid (silicone, tissue): E 100 kPa, Poisson ratio nu, the given model, 1070 kg/m^3, no Rayleigh damping.
inline MaterialSpec soft_material(double nu = 0.25, MaterialModel model = MaterialModel::kSprings) {
  MaterialSpec m;
  m.enabled = true;
  m.young_modulus_Pa = 1e5;
  m.poisson_ratio = nu;
  m.model = model;
  m.density_kg_per_m3 = 1070.0;
  return m;
}

/// An empty folder under this test process's temp_root() (removed with it at exit).
inline std::string fresh_dir(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(temp_root()) / name;
  std::filesystem::remove_all(p);
  return p.string();
}

/// Path of a file in the source tree.
inline std::string source_path(const std::string& rel) { return std::string(PALPATE_SOURCE_DIR) + "/" + rel; }

}  // namespace palpate::test
