// The graded zone: cells split a level at a time around the contact, no two touching cells more than one level
// apart, reaching twice as far into the body as along its surface; and the lattice built on it (hanging nodes in
// the middle of an edge or face of a cell one level coarser, whose corners do not hang).
#include "sim/lattice/graded_zone.h"

#include <gtest/gtest.h>

#include "sim/pressed_rest.h"

#include <random>

#include "sim/lattice/forces.h"
#include "sim/lattice/hanging.h"
#include "sim/solvers/integrator.h"
#include "sim/lattice/refined_lattice.h"
#include "sim/lattice/region.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

using test::make_box_model;

// The 4 cm box (level 3: 1 cm cells) graded down to level 5 (2.5 mm) around p_m.
constexpr int kCoarse = 3, kFine = 5;

LatticeSpec graded_spec() {
  LatticeSpec s;
  s.level = kCoarse;
  s.radius_cells = 64;
  s.fix_floor = true;
  s.integrator = IntegratorKind::kImplicitEuler;
  s.material = test::soft_material();
  s.material.density_kg_per_m3 = 1000.0;
  s.material.stiffness_damping_s = 0.02;
  return s;
}

// A leaf's box in fine cells: lo (inclusive) and its edge.
struct FineBox {
  CellCoord lo;
  int span = 1;
};

FineBox fine_box(const GridHierarchy& grid, const LeafCell& c) {
  const int s = 1 << (kFine - c.level);
  const CellCoord g = grid.coord_of(c.index, c.level);
  return {{g.i * s, g.j * s, g.k * s}, s};
}

// Whether two closed boxes share a face, an edge or a corner.
bool touch(const FineBox& a, const FineBox& b) {
  auto axis = [](int lo_a, int sa, int lo_b, int sb) { return lo_a <= lo_b + sb && lo_b <= lo_a + sa; };
  return axis(a.lo.i, a.span, b.lo.i, b.span) && axis(a.lo.j, a.span, b.lo.j, b.span) && axis(a.lo.k, a.span, b.lo.k, b.span);
}

TEST(GradedZone, TouchingCellsAreWithinOneLevelAndTileTheRegion) {
  // the contact 0.1 mm short of a level-4 plane: the level-5 cells reach x = 1 cm, a level-3 boundary the distance
  // alone would leave unsplit beside them (the 2:1 pass splits it)
  const auto box = make_box_model(0.04, kFine);
  const auto cells = region_cells(box.grid, kCoarse, {1, 1, 1}, 64);
  const Vec3 p(0.0049, 0.0, 0.02);
  const auto leaves = graded_leaves(box.grid, kCoarse, cells, kFine, p, 2e-3);
  int per_level[kFine + 1] = {};
  double volume = 0.0;
  for (const LeafCell& c : leaves) {
    ++per_level[c.level];
    volume += std::pow(box.grid.cell_size_m(c.level), 3);
  }
  EXPECT_GT(per_level[3], 0);
  EXPECT_GT(per_level[4], 0);
  EXPECT_GT(per_level[5], 0);
  EXPECT_NEAR(volume, 0.04 * 0.04 * 0.04, 1e-12);  // the whole (solid) box, once
  int worst = 0;
  for (std::size_t a = 0; a < leaves.size(); ++a)
    for (std::size_t b = a + 1; b < leaves.size(); ++b)
      if (touch(fine_box(box.grid, leaves[a]), fine_box(box.grid, leaves[b])))
        worst = std::max(worst, std::abs(leaves[a].level - leaves[b].level));
  EXPECT_EQ(worst, 1);
}

TEST(GradedZone, ReachesTwiceAsFarIntoTheBodyAsAlongItsSurface) {
  const auto box = make_box_model(0.04, kFine);
  const auto cells = region_cells(box.grid, kCoarse, {1, 1, 1}, 64);
  const Vec3 top(0.0, 0.0, 0.02);
  EXPECT_LT((inward_direction(box.grid, kFine, top) - Vec3(0.0, 0.0, -1.0)).norm(), 1e-9);
  EXPECT_EQ(inward_direction(box.grid, kFine, Vec3(0.001, 0.002, -0.003)), Vec3::Zero());  // solid all round
  // radius 3 mm: the level-4 cells (5 mm) split to level 5 are the 2 x 2 at the surface (the next ones out are 5 mm
  // away) and the 2 x 2 under them (5 mm down, counted as 2.5): 8 cells, 64 fine leaves
  const auto leaves = graded_leaves(box.grid, kCoarse, cells, kFine, top, 3e-3);
  int fine = 0;
  for (const LeafCell& c : leaves) fine += c.level == kFine;
  EXPECT_EQ(fine, 64);
}

// The graded lattice around the contact of the first test.
Lattice graded_box(const test::BoxModel& box) {
  const auto cells = region_cells(box.grid, kCoarse, {1, 1, 1}, 64);
  return build_refined_lattice(box.grid, graded_spec(), cells, kFine,
                               graded_leaves(box.grid, kCoarse, cells, kFine, Vec3(0.0049, 0.0, 0.02), 2e-3))
      .value();
}

TEST(GradedZone, HangingNodesAreMidpointsOfCornersThatDoNotHangAndFoldIsTheSpreadTransposed) {
  const auto box = make_box_model(0.04, kFine);
  const Lattice lat = graded_box(box);
  ASSERT_FALSE(lat.hanging.empty());
  std::vector<uint8_t> hangs(lat.num_nodes(), 0);
  mark_hanging(lat, &hangs);
  int chained = 0;
  for (const HangingNode& h : lat.hanging) {
    // one level coarser: the middle of an edge (2 masters, 1/2 each) or of a face (4, 1/4 each)
    ASSERT_TRUE(h.count == 2 || h.count == 4) << h.count;
    for (int k = 0; k < h.count; ++k) {
      EXPECT_DOUBLE_EQ(h.weight[static_cast<std::size_t>(k)], 1.0 / h.count);
      chained += hangs[static_cast<std::size_t>(h.master[static_cast<std::size_t>(k)])];
    }
  }
  // no master hangs: a cell split twice fills its parent to the parent's boundary, so a cell touching that parent at
  // a hanging node's master would touch a cell two levels finer, which the 2:1 pass forbids
  EXPECT_EQ(chained, 0);
  // <P q, f> = <q, P^T f> for q zero at the hanging nodes: spread in list order and fold in reverse are transposes
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> q(lat.num_nodes()), f(lat.num_nodes());
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    q[i] = hangs[i] ? Vec3::Zero() : Vec3(u(rng), u(rng), u(rng));
    f[i] = Vec3(u(rng), u(rng), u(rng));
  }
  std::vector<Vec3> pq = q, ptf = f;
  spread_hanging(lat, &pq);
  fold_hanging(lat, &ptf);
  double lhs = 0.0, rhs = 0.0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) lhs += pq[i].dot(f[i]), rhs += q[i].dot(ptf[i]);
  EXPECT_NEAR(lhs, rhs, 1e-12 * std::abs(lhs));
  // and the mass is the solid's, each cell giving its own
  double m = 0.0;
  for (double kg : lat.mass_kg) m += kg;
  EXPECT_NEAR(m, 1000.0 * 0.04 * 0.04 * 0.04, 1e-9);
}

TEST(GradedZone, ImplicitEulerComesToTheStaticRestWithHangingNodesOnTheirFaces) {
  const auto box = make_box_model(0.04, kFine);
  Lattice lat = graded_box(box);
  const Vec3 top(0.0049, 0.0, 0.02);
  test::expect_pressed_rest_on_faces(lat, top);
}

}  // namespace
}  // namespace palpate
