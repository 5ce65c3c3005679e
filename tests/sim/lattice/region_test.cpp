// Region following (move, keep deformed cells, carry state) and rest detection.
#include <gtest/gtest.h>

#include "sim/lattice/region.h"
#include "sim/solvers/rest.h"
#include "sim/sim_test_util.h"

namespace palpate {
namespace {

struct Fixture {
  test::BoxModel box = test::make_box_model(0.08, 4);  // 8^3 solid cells of 1 cm
  LatticeSpec spec = test::spec_for(4, 40, 20, 10);
  Lattice at(const CellCoord& c, int radius) {
    spec.radius_cells = radius;
    return build_lattice(box.grid, spec, region_cells(box.grid, 4, c, radius)).value();
  }
};

TEST(Region, ContactLeavesWhenItReachesTheOuterRing) {
  Fixture f;
  const Lattice lat = f.at({3, 3, 3}, 2);
  EXPECT_FALSE(contact_leaves_region(lat, {3, 3, 3}, {3, 3, 3}, 2));
  EXPECT_FALSE(contact_leaves_region(lat, {3, 3, 3}, {4, 2, 3}, 2));
  EXPECT_TRUE(contact_leaves_region(lat, {3, 3, 3}, {5, 3, 3}, 2));
  EXPECT_TRUE(contact_leaves_region(lat, {3, 3, 3}, {7, 7, 7}, 2));
}

TEST(Region, MovedRegionKeepsDeformedCellsAndCarriesTheirState) {
  Fixture f;
  Lattice old = f.at({2, 2, 2}, 1);
  // deform one free node in the middle of the old region
  std::size_t mid = 0;
  for (std::size_t i = 0; i < old.num_nodes(); ++i)
    if (!old.fixed[i]) mid = i;
  old.x_m[mid] += Vec3(1e-3, 0, 0);
  old.v_m_per_s[mid] = Vec3(0, 0.01, 0);
  const auto cells = followed_region_cells(f.box.grid, old, {5, 5, 5}, 1, 1e-9);
  // the new 27 cells around (5,5,5) plus the 8 old cells around the displaced node (they do not overlap)
  EXPECT_EQ(cells.size(), 27u + 8u);
  Lattice moved = build_lattice(f.box.grid, f.spec, cells).value();
  EXPECT_NE(moved.revision, old.revision);
  EXPECT_GE(carry_state(old, &moved), 1);
  bool found = false;
  for (std::size_t i = 0; i < moved.num_nodes(); ++i)
    if (moved.grid_node[i] == old.grid_node[mid]) {
      found = true;
      EXPECT_EQ(moved.x_m[i], old.x_m[mid]);
      EXPECT_EQ(moved.v_m_per_s[i], old.v_m_per_s[mid]);
    }
  EXPECT_TRUE(found);
  // with nothing deformed, only the new cells remain
  old.reset_to_rest();
  EXPECT_EQ(followed_region_cells(f.box.grid, old, {5, 5, 5}, 1, 1e-9).size(), 27u);
}

TEST(Rest, RestingLatticeIsDetectedAndAKickOrAPushWakesIt) {
  Fixture f;
  Lattice lat = f.at({3, 3, 3}, 2);
  std::vector<Vec3> scratch;
  EXPECT_TRUE(lattice_at_rest(lat, {}, 1e-12, 1e-6, &scratch));
  std::vector<Vec3> push(lat.num_nodes(), Vec3::Zero());
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (!lat.fixed[i]) {
      push[i] = Vec3(0, 0, 1e-3);
      break;
    }
  EXPECT_FALSE(lattice_at_rest(lat, push, 1e-12, 1e-6, &scratch));
  test::kick(&lat, 1e-9);
  EXPECT_FALSE(lattice_at_rest(lat, {}, 1e-12, 1e-6, &scratch));
  // damped, it comes to rest again
  IntegratorWorkspace ws;
  int frames = 0;
  while (!lattice_at_rest(lat, {}, 1e-12, 1e-6, &scratch) && frames < 6000) {
    step_lattice(&lat, test::opts(IntegratorKind::kImplicitEuler), 1.0 / 60.0, {}, &ws);
    ++frames;
  }
  EXPECT_LT(frames, 6000);
}

}  // namespace
}  // namespace palpate
