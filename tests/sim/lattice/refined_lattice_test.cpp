// The refined lattice: fine cells in a zone, coarse ones around it, hanging nodes on the coarse faces between.
#include "sim/lattice/refined_lattice.h"

#include <gtest/gtest.h>

#include "sim/pressed_rest.h"

#include "sim/lattice/forces.h"
#include "sim/lattice/hanging.h"
#include "sim/solvers/integrator.h"
#include "sim/material/material.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

using test::make_box_model;

LatticeSpec material_spec(int level) {
  LatticeSpec s;
  s.level = level;
  s.radius_cells = 64;
  s.integrator = IntegratorKind::kImplicitEuler;
  s.material = test::soft_material();
  s.material.density_kg_per_m3 = 1000.0;
  s.material.stiffness_damping_s = 0.02;
  return s;
}

// The 4 cm box at coarse level 3 (4 cells per axis), the cells within `radius_m` of the centre split to fine_level.
Lattice refined_box(const test::BoxModel& box, int fine_level, double radius_m) {
  const LatticeSpec spec = material_spec(3);
  const auto cells = region_cells(box.grid, 3, {1, 1, 1}, 64);
  return build_refined_lattice(box.grid, spec, cells, fine_level, cells_near(box.grid, 3, cells, Vec3::Zero(), radius_m))
      .value();
}

TEST(RefinedLattice, NodesCellsAndHangingNodesOfASplitCentre) {
  const auto box = make_box_model(0.04, 4);
  // the 8 cells around the centre split in 2 per axis: 56 coarse + 64 fine cells
  const Lattice lat = refined_box(box, 4, 1e-3);
  ASSERT_EQ(lat.cells.size(), 56u + 64u);
  // nodes: the 5^3 coarse vertices plus the fine vertices of the split 2 x 2 x 2 block (5^3) not on coarse vertices
  EXPECT_EQ(lat.num_nodes(), 125u + 125u - 27u);
  // hanging: the split block's fine vertices on its surface (98 of its 5^3) that are not coarse vertices (26)
  EXPECT_EQ(lat.hanging.size(), 98u - 26u);
  for (const HangingNode& h : lat.hanging) {
    double sum = 0.0;
    for (int k = 0; k < h.count; ++k) sum += h.weight[static_cast<std::size_t>(k)];
    EXPECT_NEAR(sum, 1.0, 1e-12);
    EXPECT_TRUE(h.count == 2 || h.count == 4) << h.count;
  }
  // the material's mass is the same as the uniform lattice's (each cell gives its own)
  double m = 0.0;
  for (double kg : lat.mass_kg) m += kg;
  EXPECT_NEAR(m, 1000.0 * 0.04 * 0.04 * 0.04, 1e-9);
}

TEST(RefinedLattice, UniformStrainLeavesLittleForceInsideAcrossTheCoarseFineFaces) {
  // the patch test: an affine deformation of the refined lattice, hanging nodes on their faces. A uniform lattice
  // has no force at any interior node; across a coarse face a little is left once the hanging nodes' forces are
  // folded onto their masters (each cell's body diagonal gives its corners a force odd in all three axes, which the
  // 8 cells around a uniform node cancel and a coarse face does not): 2.0 % / 2.5 % of the largest nodal force at
  // 2 / 4 fine cells a coarse edge. Without the fold the hanging nodes keep their one-sided pull.
  for (int fine_level : {4, 5}) {
    const auto box = make_box_model(0.04, fine_level);
    Lattice lat = refined_box(box, fine_level, 1e-3);
    ASSERT_FALSE(lat.hanging.empty());
    Mat3 g;
    g << 1e-3, 2e-4, -3e-4, 1e-4, -5e-4, 4e-4, -2e-4, 3e-4, 8e-4;
    for (std::size_t i = 0; i < lat.num_nodes(); ++i) lat.x_m[i] = lat.rest_m[i] + g * lat.rest_m[i];
    std::vector<Vec3> f;
    compute_forces(lat, lat.x_m, lat.v_m_per_s, {}, &f);
    auto largest_inside = [&](const std::vector<Vec3>& forces) {
      double m = 0.0;
      for (std::size_t i = 0; i < lat.num_nodes(); ++i)
        if (lat.rest_m[i].cwiseAbs().maxCoeff() < 0.02 - 1e-9) m = std::max(m, forces[i].norm());
      return m;
    };
    double largest = 0.0;
    for (const Vec3& v : f) largest = std::max(largest, v.norm());
    const double unfolded = largest_inside(f);
    fold_hanging(lat, &f);
    const double folded = largest_inside(f);
    EXPECT_GT(largest, 1e-3);  // the strain loads the springs
    EXPECT_LT(folded, 0.03 * largest) << "fine level " << fine_level;
    EXPECT_LT(folded, 0.2 * unfolded) << "fine level " << fine_level;
  }
}

TEST(RefinedLattice, ImplicitEulerKeepsHangingNodesOnTheirFacesAndComesToTheStaticRest) {
  // a pressed block: the top centre node pushed down; the refined lattice steps to rest with its hanging nodes on
  // the coarse faces, and the rest has no free-coordinate force left
  const auto box = make_box_model(0.04, 5);
  LatticeSpec spec = material_spec(3);
  spec.fix_floor = true;
  const auto cells = region_cells(box.grid, 3, {1, 1, 1}, 64);
  const Vec3 top(0.0, 0.0, 0.02);
  Lattice lat =
      build_refined_lattice(box.grid, spec, cells, 5, cells_near(box.grid, 3, cells, top, 1e-3)).value();
  test::expect_pressed_rest_on_faces(lat, top);
}

TEST(RefinedLattice, CarriedStateKeepsSharedNodesAndInterpolatesNewOnes) {
  const auto box = make_box_model(0.04, 4);
  const LatticeSpec spec = material_spec(3);
  const auto cells = region_cells(box.grid, 3, {1, 1, 1}, 64);
  Lattice from = build_refined_lattice(box.grid, spec, cells, 4, cells_near(box.grid, 3, cells, Vec3(-0.01, 0, 0), 1e-3)).value();
  Lattice to = build_refined_lattice(box.grid, spec, cells, 4, cells_near(box.grid, 3, cells, Vec3(0.01, 0, 0), 1e-3)).value();
  // an affine displacement is carried exactly, wherever a node of `to` comes from
  Mat3 g;
  g << 1e-3, 0, 2e-4, 0, -1e-3, 0, 3e-4, 0, 5e-4;
  for (std::size_t i = 0; i < from.num_nodes(); ++i) from.x_m[i] = from.rest_m[i] + g * from.rest_m[i];
  const int carried = carry_state_refined(box.grid, from, &to);
  int free_nodes = 0;
  for (std::size_t i = 0; i < to.num_nodes(); ++i) {
    free_nodes += to.fixed[i] ? 0 : 1;
    if (!to.fixed[i]) {
      EXPECT_LT((to.x_m[i] - (to.rest_m[i] + g * to.rest_m[i])).norm(), 1e-14);
    }
  }
  EXPECT_EQ(carried, free_nodes);
}

TEST(RefinedLattice, RefusesWhatItCannotHold) {
  const auto box = make_box_model(0.04, 4);
  const auto cells = region_cells(box.grid, 3, {1, 1, 1}, 64);
  LatticeSpec spec = material_spec(3);
  auto same = build_refined_lattice(box.grid, spec, cells, 3, cells);
  ASSERT_FALSE(same);
  EXPECT_NE(same.error().message.find("fine level 3"), std::string::npos) << same.error().message;
  spec.material.enabled = false;
  auto raw = build_refined_lattice(box.grid, spec, cells, 4, cells);
  ASSERT_FALSE(raw);
  EXPECT_NE(raw.error().message.find("needs a material"), std::string::npos) << raw.error().message;
}

}  // namespace
}  // namespace palpate
