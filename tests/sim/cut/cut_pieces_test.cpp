// The pieces a cut frees, stepped as a lattice of their own: its nodes and springs are the free ones, it falls as a
// free body does, and written back it moves those nodes of the whole lattice and no other.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim/cut/cut.h"
#include "sim/cut/cut_pieces.h"
#include "sim/solvers/integrator.h"
#include "sim/contact/piece_contact.h"
#include "sim/sim_test_util.h"

namespace palpate {
namespace {

// A block cut level at z = 0.013: the top comes free of the floor's fixed nodes. Falling from rest for t seconds
// (springs at rest length, one uniform gravity) it drops g t^2 / 2 as one body.
TEST(CutPieces, APieceCutFreeIsSteppedAloneAndFallsAsAFreeBody) {
  const auto box = test::make_box_model(0.08, 4, 8);
  LatticeSpec spec = test::spec_for(3, 40, 20, 10);
  spec.fix_floor = true;
  spec.gravity_m_per_s2 = Vec3(0, 0, -9.81);
  Lattice whole = build_lattice(box.grid, spec, region_cells(box.grid, 3, {1, 1, 1}, 8)).value();
  const BladeQuad level_cut{{-0.06, -0.06, 0.013}, {0.06, -0.06, 0.013}, {-0.06, 0.06, 0.013}, {0.06, 0.06, 0.013}};
  ASSERT_GT(cut_springs(&whole, {level_cut}), 0);
  PieceContact contact;
  contact.update(whole, box.grid);
  const std::vector<int32_t>& free = contact.free_nodes();
  ASSERT_FALSE(free.empty());

  PieceLattice pieces;
  EXPECT_TRUE(pieces.update(whole, free));
  EXPECT_FALSE(pieces.update(whole, free));  // the same nodes and springs: not rebuilt
  const Lattice& p = pieces.lattice();
  ASSERT_EQ(p.num_nodes(), free.size());
  std::size_t inside = 0;
  for (const Spring& s : whole.springs) inside += whole.rest_m[s.a].z() > 0.013 && whole.rest_m[s.b].z() > 0.013;
  EXPECT_EQ(p.springs.size(), inside);
  for (std::size_t i = 0; i < p.num_nodes(); ++i) {
    EXPECT_GT(p.rest_m[i].z(), 0.013);
    EXPECT_EQ(p.fixed[i], 0);
  }

  IntegratorWorkspace ws;
  const int frames = 12;
  for (int f = 0; f < frames; ++f)
    step_lattice(&pieces.lattice(), IntegratorKind::kSymplecticEuler, 1.0 / 60.0, 256, {}, &ws);
  const std::vector<Vec3> before = whole.x_m;
  pieces.push(&whole);
  const double t_s = frames / 60.0, drop_m = 0.5 * 9.81 * t_s * t_s;
  std::vector<uint8_t> in_piece(whole.num_nodes(), 0);
  for (int32_t n : free) in_piece[static_cast<std::size_t>(n)] = 1;
  for (std::size_t i = 0; i < whole.num_nodes(); ++i) {
    if (!in_piece[i]) {
      EXPECT_EQ(whole.x_m[i], before[i]) << "node " << i;  // the body is not moved
      continue;
    }
    // every node of the piece has dropped as the free body does (symplectic Euler's step error: under 10 %)
    EXPECT_NEAR(whole.rest_m[i].z() - whole.x_m[i].z(), drop_m, 0.1 * drop_m) << "node " << i;
    EXPECT_NEAR(whole.x_m[i].x(), whole.rest_m[i].x(), 1e-9);
  }
  // read back after the whole lattice moved them (the floor, the body)
  whole.x_m[static_cast<std::size_t>(free.front())].z() = 1.0;
  pieces.pull(whole);
  EXPECT_EQ(pieces.lattice().x_m.front().z(), 1.0);
}

}  // namespace
}  // namespace palpate
