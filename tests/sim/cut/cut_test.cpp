// Cutting a block: springs and mesh split by the blade's swept surface, side binding, validity.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "core/binding.h"
#include "sim/cut/cut_model.h"
#include "sim/solvers/integrator.h"
#include "sim/contact/piece_contact.h"
#include "sim/cut_block.h"
#include "sim/sim_test_util.h"

namespace palpate {
namespace {

constexpr double kSide_m = test::kCutBlockSide_m;  // block from -0.04 to 0.04; level 3 cells of 2 cm, mesh quads of 1 cm
constexpr int kLevel = test::kCutBlockLevel;
using Block = test::CutBlock;

// The plane x = x0 swept through the y range [y0, y1] over the whole height: one quad.
BladeQuad plane_x(double x0, double y0 = -0.06, double y1 = 0.06) {
  return {{x0, y0, -0.06}, {x0, y0, 0.06}, {x0, y1, -0.06}, {x0, y1, 0.06}};
}

// Mesh edges whose ends lie on both sides of x = x0, and triangles with corners on both sides.
void straddling(const TriMesh& m, double x0, int* edges, int* tris) {
  std::set<std::pair<int32_t, int32_t>> e;
  *tris = 0;
  for (const auto& t : m.triangles) {
    int below = 0;
    for (int k = 0; k < 3; ++k) {
      const int32_t a = t[k], b = t[(k + 1) % 3];
      below += m.vertices_m[a].x() < x0;
      if ((m.vertices_m[a].x() < x0) != (m.vertices_m[b].x() < x0)) e.insert({std::min(a, b), std::max(a, b)});
    }
    *tris += below == 1 || below == 2;
  }
  *edges = static_cast<int>(e.size());
}

TEST(Cut, CulledSegmentTestsFindWhatTestingEveryQuadFinds) {
  // a stroke of 100 quads (six runs and a partial one) along an arc that turns and dips, against 4000 segments
  // of all lengths around it: hit or not and the first crossing as testing every quad without boxes
  std::vector<BladeQuad> quads;
  auto edge = [](int i, Vec3* tip, Vec3* end) {
    const double a = 0.03 * i;
    *tip = Vec3(0.05 * std::cos(a), 0.05 * std::sin(a), -0.02 + 0.0002 * i);
    *end = *tip + Vec3(0.01 * std::sin(a), 0.0, 0.04);
  };
  for (int i = 0; i < 100; ++i) {
    BladeQuad q;
    edge(i, &q.tip0_m, &q.end0_m);
    edge(i + 1, &q.tip1_m, &q.end1_m);
    quads.push_back(q);
  }
  const CutQuads set(quads);
  ASSERT_EQ(set.chunk_box.size(), 7u);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.07, 0.07), len(0.0, 1.0);
  int hits = 0;
  for (int k = 0; k < 4000; ++k) {
    const Vec3 p(u(rng), u(rng), u(rng));
    const Vec3 q = p + (k % 2 ? len(rng) : std::pow(len(rng), 3.0)) * 4.0 * Vec3(u(rng), u(rng), u(rng));
    bool any = false;
    double first = 2.0;
    for (const BladeQuad& quad : quads) {
      double t = 2.0;
      if (segment_crosses_quad(p, q, quad, &t)) {
        any = true;
        first = std::min(first, t);
      }
    }
    double t = -1.0;
    ASSERT_EQ(segment_crosses_any(p, q, set), any) << "segment " << k;
    ASSERT_EQ(segment_crosses_any(p, q, set, &t), any) << "segment " << k;
    if (any) {
      ASSERT_EQ(t, first) << "segment " << k;
    }
    hits += any;
  }
  std::printf("%d of 4000 segments cross the stroke\n", hits);
  EXPECT_GT(hits, 150);  // a good share of them cross it (203)
  EXPECT_LT(hits, 3800);
}

TEST(Cut, CuttingABlockInTwoLeavesTwoConsistentPieces) {
  Block b;
  const std::size_t tris0 = b.cut.triangles().size();
  const int x_edges = [&] { int e = 0, t = 0; straddling(b.box.mesh, 0.003, &e, &t); return e; }();
  const int x_tris = [&] { int e = 0, t = 0; straddling(b.box.mesh, 0.003, &e, &t); return t; }();
  const std::vector<BladeQuad> quads{plane_x(0.003)};
  const CutReport rep = b.cut.apply_quads(quads, &b.lat, &b.vertices);

  // the split formula: a planar cut through crosses each straddling triangle twice (1 -> 3)
  EXPECT_GT(rep.springs_cut, 0);
  EXPECT_EQ(rep.split.edges_cut, x_edges);
  EXPECT_EQ(rep.split.tris_two_cut, x_tris);
  EXPECT_EQ(rep.split.tris_one_cut + rep.split.tris_three_cut, 0);
  EXPECT_EQ(b.cut.triangles().size(), tris0 + 2 * static_cast<std::size_t>(x_tris));
  EXPECT_EQ(rep.split.triangles_added, 2 * x_tris);
  EXPECT_EQ(b.vertices.size(), b.box.mesh.vertices_m.size() + 2 * static_cast<std::size_t>(x_edges));
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");

  // two pieces of springs, each on one side
  std::vector<int32_t> label;
  ASSERT_EQ(spring_components(b.lat, &label), 2);
  for (const Spring& s : b.lat.springs) {
    EXPECT_EQ(b.lat.rest_m[s.a].x() < 0.003, b.lat.rest_m[s.b].x() < 0.003);
    EXPECT_FALSE(segment_crosses_quad(b.lat.x_m[s.a], b.lat.x_m[s.b], quads[0]));
  }
  // two pieces of triangles, each on one side (new rim vertices lie on the plane, moved off it by the offset)
  std::vector<int32_t> tri_label;
  ASSERT_EQ(triangle_components(b.vertices.size(), b.cut.triangles(), &tri_label), 2);
  std::array<std::set<bool>, 2> sides;
  for (std::size_t t = 0; t < tri_label.size(); ++t)
    for (int32_t v : b.cut.triangles()[t]) {
      const double x = b.cut.rest_vertices_m()[v].x();
      if (std::abs(x - 0.003) > kBladeOffsetCells * b.lat.cell_m + 1e-12) sides[tri_label[t]].insert(x < 0.003);
    }
  EXPECT_EQ(sides[0].size(), 1u);
  EXPECT_EQ(sides[1].size(), 1u);
  EXPECT_NE(*sides[0].begin(), *sides[1].begin());
}

// Capped, a cut takes out at most the cap a call and leaves the rest crossed in the lattice, oldest first; later
// calls (with no quad) take them out in that order, and in the end the same springs are gone, in the same
// order, as one uncapped cut leaves.
TEST(Cut, ACappedCutRemovesTheSameSpringsOverSeveralCallsOldestFirst) {
  Block whole, capped;
  const std::vector<BladeQuad> quads{plane_x(0.003)};
  const int all = cut_springs(&whole.lat, quads);
  ASSERT_GT(all, 20);
  std::vector<uint64_t> deferred;
  const uint64_t rev0 = capped.lat.revision;
  EXPECT_EQ(cut_springs_capped(&capped.lat, quads, 8, &deferred), 8);
  EXPECT_NE(capped.lat.revision, rev0);  // touched: the solver sees a change
  EXPECT_EQ(deferred.size(), static_cast<std::size_t>(all - 8));
  // the springs left are still crossed ones in spring order: the first 8 crossed went
  const std::vector<uint64_t> first_wait = deferred;
  // crossing the same springs again does not queue them twice, and the oldest go first
  EXPECT_EQ(cut_springs_capped(&capped.lat, quads, 8, &deferred), 8);
  EXPECT_EQ(deferred.size(), static_cast<std::size_t>(all - 16));
  EXPECT_TRUE(std::equal(deferred.begin(), deferred.end(), first_wait.begin() + 8));
  int calls = 2;
  while (!deferred.empty()) {
    const uint64_t rev = capped.lat.revision;
    EXPECT_EQ(cut_springs_capped(&capped.lat, {}, 8, &deferred), std::min(8, all - 8 * calls));
    EXPECT_NE(capped.lat.revision, rev);
    ++calls;
  }
  EXPECT_EQ(calls, (all + 7) / 8);
  ASSERT_EQ(capped.lat.springs.size(), whole.lat.springs.size());
  for (std::size_t i = 0; i < whole.lat.springs.size(); ++i) {
    EXPECT_EQ(capped.lat.springs[i].a, whole.lat.springs[i].a);
    EXPECT_EQ(capped.lat.springs[i].b, whole.lat.springs[i].b);
  }
  EXPECT_EQ(capped.lat.springs_per_family, whole.lat.springs_per_family);
  // nothing crossed and nothing waiting: no change
  const uint64_t rev = capped.lat.revision;
  EXPECT_EQ(cut_springs_capped(&capped.lat, quads, 8, &deferred), 0);
  EXPECT_EQ(capped.lat.revision, rev);
}

// The cut model under a limit: the mesh is cut at once, the springs over the following applies (which run with
// no quad pending), at most the limit each or a quarter of those waiting when more wait.
TEST(Cut, ALimitedCutModelCutsTheMeshAtOnceAndTheSpringsOverTheNextApplies) {
  Block whole, limited;
  const std::vector<BladeQuad> quads{plane_x(0.003)};
  const CutReport w = whole.cut.apply_quads(quads, &whole.lat, &whole.vertices);
  limited.cut.set_max_springs_per_apply(4);
  const CutReport first = limited.cut.apply_quads(quads, &limited.lat, &limited.vertices);
  EXPECT_EQ(first.split.edges_cut, w.split.edges_cut);
  EXPECT_EQ(limited.cut.triangles().size(), whole.cut.triangles().size());
  EXPECT_EQ(first.springs_cut, 4);
  std::size_t waiting = limited.cut.deferred_springs();
  ASSERT_EQ(waiting, static_cast<std::size_t>(w.springs_cut - 4));
  ASSERT_GT(waiting, 16u);  // more than four times the limit: a quarter of them go
  int total = first.springs_cut;
  while (limited.cut.deferred_springs() > 0) {
    const CutReport r = limited.cut.apply(&limited.lat, &limited.vertices);
    EXPECT_EQ(r.springs_cut, std::min(static_cast<int>(waiting), std::max(4, static_cast<int>((waiting + 3) / 4))));
    total += r.springs_cut;
    waiting = limited.cut.deferred_springs();
  }
  EXPECT_EQ(total, w.springs_cut);
  EXPECT_EQ(limited.lat.springs.size(), whole.lat.springs.size());
  EXPECT_EQ(limited.cut.apply(&limited.lat, &limited.vertices).springs_cut, 0);
}

TEST(Cut, EachSideFollowsItsOwnNodes) {
  Block b;
  b.cut.apply_quads({plane_x(0.003)}, &b.lat, &b.vertices);
  // move the +x side's nodes by 1 cm along x; the -x side stays
  for (std::size_t i = 0; i < b.lat.num_nodes(); ++i)
    if (b.lat.rest_m[i].x() > 0.003) b.lat.x_m[i] = b.lat.rest_m[i] + Vec3(0.01, 0, 0);
  b.cut.deform(b.lat, &b.vertices);
  // which side a rim vertex is on: its triangle piece
  std::vector<int32_t> label;
  triangle_components(b.vertices.size(), b.cut.triangles(), &label);
  std::vector<int32_t> piece(b.vertices.size(), -1);
  for (std::size_t t = 0; t < label.size(); ++t)
    for (int32_t v : b.cut.triangles()[t]) piece[v] = label[t];
  int32_t plus_piece = -1;
  for (std::size_t v = 0; v < b.vertices.size(); ++v)
    if (b.cut.rest_vertices_m()[v].x() > 0.02) plus_piece = piece[v];
  for (std::size_t v = 0; v < b.vertices.size(); ++v) {
    const Vec3 moved = b.vertices[v] - b.cut.rest_vertices_m()[v];
    const double expect = piece[v] == plus_piece ? 0.01 : 0.0;
    EXPECT_NEAR(moved.x(), expect, 1e-12) << "vertex " << v;
    EXPECT_NEAR(moved.tail<2>().norm(), 0.0, 1e-12);
  }
  EXPECT_EQ(b.cut.orphans(), 0);
}

TEST(Cut, PartialCutLeavesOnePiece) {
  Block b;
  const CutReport rep = b.cut.apply_quads({plane_x(0.003, -0.06, 0.005)}, &b.lat, &b.vertices);
  EXPECT_GT(rep.springs_cut, 0);
  EXPECT_GT(rep.split.tris_one_cut, 0);  // where the cut ends inside
  EXPECT_EQ(static_cast<int>(b.cut.triangles().size() - b.box.mesh.triangles.size()),
            rep.split.tris_one_cut + 2 * (rep.split.tris_two_cut + rep.split.tris_three_cut));
  std::vector<int32_t> label;
  EXPECT_EQ(spring_components(b.lat, &label), 1);
  EXPECT_EQ(triangle_components(b.vertices.size(), b.cut.triangles()), 1);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
}

TEST(Cut, BladeOutsideTheObjectChangesNothing) {
  Block b;
  const std::size_t springs = b.lat.springs.size();
  const uint64_t revision = b.lat.revision;
  const CutReport rep = b.cut.apply_quads({plane_x(0.07)}, &b.lat, &b.vertices);
  EXPECT_FALSE(rep.changed());
  EXPECT_EQ(b.lat.springs.size(), springs);
  EXPECT_EQ(b.lat.revision, revision);
  EXPECT_EQ(b.cut.triangles(), b.box.mesh.triangles);
  EXPECT_EQ(b.vertices, b.box.mesh.vertices_m);
}

TEST(Cut, SamplesSweepQuadsOnlyWhileCutting) {
  Block b;
  b.cut.add_sample({0, 0, 0}, Vec3::UnitZ(), false);
  b.cut.add_sample({0.001, 0, 0}, Vec3::UnitZ(), true);
  EXPECT_TRUE(b.cut.pending().empty());  // a stroke starts: nothing swept yet
  b.cut.add_sample({0.002, 0, 0}, Vec3::UnitZ(), true);
  b.cut.add_sample({0.002, 0, 0}, Vec3::UnitZ(), true);  // not moved: no quad
  ASSERT_EQ(b.cut.pending().size(), 1u);
  EXPECT_NEAR((b.cut.pending()[0].end1_m - Vec3(0.002, 0, 0.2)).norm(), 0.0, 1e-15);
  b.cut.add_sample({0.003, 0, 0}, Vec3::UnitZ(), false);
  b.cut.add_sample({0.004, 0, 0}, Vec3::UnitZ(), true);
  EXPECT_EQ(b.cut.pending().size(), 1u);
  b.cut.apply(&b.lat, &b.vertices);
  EXPECT_TRUE(b.cut.pending().empty());
}

TEST(Cut, CutAlongAnExistingCutAndACrossingCutStayValid) {
  Block b;
  b.cut.apply_quads({plane_x(0.003)}, &b.lat, &b.vertices);
  const std::size_t tris = b.cut.triangles().size();
  // the same cut again: the rim vertices lie on it, nothing is split twice
  const CutReport again = b.cut.apply_quads({plane_x(0.003)}, &b.lat, &b.vertices);
  EXPECT_EQ(again.springs_cut, 0);
  EXPECT_EQ(b.cut.triangles().size(), tris);
  // a cut just beside it and one across it
  b.cut.apply_quads({plane_x(0.0031)}, &b.lat, &b.vertices);
  const BladeQuad across{{-0.06, 0.013, -0.06}, {-0.06, 0.013, 0.06}, {0.06, 0.013, -0.06}, {0.06, 0.013, 0.06}};
  const CutReport cross = b.cut.apply_quads({across}, &b.lat, &b.vertices);
  EXPECT_GT(cross.springs_cut, 0);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
  std::vector<int32_t> label;
  EXPECT_EQ(spring_components(b.lat, &label), 4);
  // the cut beside the first shaves a 0.1 mm strip off the +x face of the first one, itself cut in two by the
  // crossing one: four pieces and two strips
  EXPECT_EQ(triangle_components(b.vertices.size(), b.cut.triangles()), 6);
}

TEST(Cut, APieceCutFreeFallsToTheFloorWithoutNaN) {
  Block b;
  b.spec.fix_floor = true;
  b.spec.gravity_m_per_s2 = Vec3(0, 0, -9.81);
  b.lat = build_lattice(b.box.grid, b.spec, region_cells(b.box.grid, kLevel, {1, 1, 1}, 8)).value();
  const BladeQuad level_cut{{-0.06, -0.06, 0.013}, {0.06, -0.06, 0.013}, {-0.06, 0.06, 0.013}, {0.06, 0.06, 0.013}};
  b.cut.apply_quads({level_cut}, &b.lat, &b.vertices);
  EXPECT_GT(free_nodes(b.lat), 0);
  IntegratorWorkspace ws;
  const double floor_z = -kSide_m / 2;
  for (int f = 0; f < 120; ++f) {
    step_lattice(&b.lat, IntegratorKind::kSymplecticEuler, 1.0 / 60.0, 256, {}, &ws);
    apply_floor(&b.lat, floor_z);
  }
  for (std::size_t i = 0; i < b.lat.num_nodes(); ++i) EXPECT_GE(b.lat.x_m[i].z(), floor_z);
  b.cut.deform(b.lat, &b.vertices);
  double top = -1.0;
  for (const Vec3& v : b.vertices) {
    ASSERT_TRUE(v.allFinite());
    // the floor holds nodes: a surface bound below its nodes reaches into it by less than a cell
    EXPECT_GE(v.z(), floor_z - b.lat.cell_m);
    top = std::max(top, v.z());
  }
  EXPECT_LT(top, 0.013);  // the top piece has come down
}

}  // namespace
}  // namespace palpate

namespace palpate {
namespace {

TEST(Cut, ManyThinSweepsCutLikeOneQuad) {
  Block b;
  // the plane x = 0.003 swept in 1 mm steps of y, applied 16 sweeps at a time like frames of servo samples
  for (int i = 0; i < 120; ++i) {
    const double y = -0.06 + 0.001 * i;
    b.cut.add_sample({0.003, y, -0.06}, Vec3::UnitZ(), true);
    if (i % 16 == 15) b.cut.apply(&b.lat, &b.vertices);
  }
  b.cut.apply(&b.lat, &b.vertices);
  std::vector<int32_t> label;
  EXPECT_EQ(spring_components(b.lat, &label), 2);
  EXPECT_EQ(triangle_components(b.vertices.size(), b.cut.triangles()), 2);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
}


TEST(Cut, ASlowCutThroughAMovingBlockSeparatesIt) {
  Block b;
  b.spec = test::spec_for(kLevel, 400, 200, 100);
  b.spec.fix_floor = true;
  // gravity with a sideways pull: the block leans in x while the blade passes, nodes drifting across its plane
  b.spec.gravity_m_per_s2 = Vec3(4.0, 0, -9.81);
  b.lat = build_lattice(b.box.grid, b.spec, region_cells(b.box.grid, kLevel, {1, 1, 1}, 8)).value();
  IntegratorWorkspace ws;
  const double x_blade = 0.003;
  int drifted = 0;  // node samples on the other side of the blade from where they rest
  for (int i = 0; i < 240; ++i) {
    const double y = -0.06 + 0.0005 * i;
    b.cut.add_sample({x_blade, y, -0.06}, Vec3::UnitZ(), true);
    if (i % 8 != 7) continue;
    b.cut.apply(&b.lat, &b.vertices);
    step_lattice(&b.lat, IntegratorKind::kSymplecticEuler, 1.0 / 60.0, 256, {}, &ws);
    b.cut.deform(b.lat, &b.vertices);
    for (std::size_t n = 0; n < b.lat.num_nodes(); ++n)
      drifted += (b.lat.rest_m[n].x() < x_blade) != (b.lat.x_m[n].x() < x_blade);
  }
  b.cut.apply(&b.lat, &b.vertices);
  EXPECT_GT(drifted, 0);
  std::vector<int32_t> label;
  EXPECT_EQ(spring_components(b.lat, &label), 2);
  EXPECT_EQ(triangle_components(b.vertices.size(), b.cut.triangles()), 2);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
  for (const Vec3& v : b.vertices) ASSERT_TRUE(v.allFinite());
}


TEST(Cut, WorldPointsMapToRestThroughADeformedLattice) {
  Block b;
  // an affine deformation, which trilinear cells reproduce exactly: the map back is exact inside and outside
  Mat3 A;
  A << 1.1, 0.2, 0.0, -0.1, 0.9, 0.15, 0.05, 0.0, 1.2;
  const Vec3 t(0.004, -0.003, 0.01);
  for (std::size_t n = 0; n < b.lat.num_nodes(); ++n) b.lat.x_m[n] = A * b.lat.rest_m[n] + t;
  for (const Vec3& r : {Vec3(0.003, -0.017, 0.021), Vec3(-0.039, 0.038, -0.001), Vec3(0.0, 0.0, 0.05)})
    EXPECT_NEAR((world_to_rest(b.lat, b.box.grid, A * r + t) - r).norm(), 0.0, 1e-9) << r.transpose();
  std::vector<BladeQuad> rest;
  RestEdge last;
  quads_to_rest(b.lat, b.box.grid, {plane_x(0.003)}, &last, &rest);
  EXPECT_EQ(rest.size(), 6u);  // a 12 cm blade edge in 2 cm cells
  EXPECT_EQ(last.pieces, 6);
}

}  // namespace
}  // namespace palpate

namespace palpate {
namespace {

// A blade along a row of mesh vertices and lattice nodes (the plane x = 0 holds a column of each): before the
// quads were moved off their plane, no edge was split (every crossing at an end) and the nodes on it lost their
// springs on both sides. Now the mesh and the lattice each come apart in two, every vertex of the row on one side.
TEST(Cut, ABladeAlongARowOfVerticesAndNodesStillSplits) {
  Block b;
  int on_plane_v = 0, on_plane_n = 0;
  for (const Vec3& v : b.box.mesh.vertices_m) on_plane_v += std::abs(v.x()) < 1e-12;
  for (const Vec3& r : b.lat.rest_m) on_plane_n += std::abs(r.x()) < 1e-12;
  ASSERT_GT(on_plane_v, 20);
  ASSERT_GT(on_plane_n, 20);
  const CutReport rep = b.cut.apply_quads({plane_x(0.0)}, &b.lat, &b.vertices);
  EXPECT_GT(rep.split.triangles_added, 0);
  std::vector<int32_t> label;
  EXPECT_EQ(spring_components(b.lat, &label), 2);
  EXPECT_EQ(triangle_components(b.vertices.size(), b.cut.triangles()), 2);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
  // no node lost every spring (a node alone would fall away and drag its vertices into spikes)
  std::vector<int> springs_of(b.lat.num_nodes(), 0);
  for (const Spring& s : b.lat.springs) ++springs_of[s.a], ++springs_of[s.b];
  for (std::size_t i = 0; i < springs_of.size(); ++i) EXPECT_GT(springs_of[i], 0) << "node " << i;
}

// A split visits only the triangles near the sweep: a short cut into a corner of a fine mesh leaves the triangles
// away from it untouched (same index, same vertices) and adds at most two triangles per crossed one.
TEST(Cut, ASplitTouchesOnlyTheTrianglesNearTheSweep) {
  Block b;
  const auto before = b.cut.triangles();
  const CutReport rep = b.cut.apply_quads({plane_x(0.013, 0.02, 0.06)}, &b.lat, &b.vertices);
  const int crossed = rep.split.tris_one_cut + rep.split.tris_two_cut + rep.split.tris_three_cut;
  ASSERT_GT(crossed, 0);
  EXPECT_LE(rep.split.triangles_added, 2 * crossed);
  EXPECT_LT(rep.split.triangles_tested, static_cast<int>(before.size()) / 4);
  int changed = 0;
  for (std::size_t t = 0; t < before.size(); ++t) changed += b.cut.triangles()[t] != before[t];
  EXPECT_EQ(changed, crossed);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
}

// Under a split budget a stroke is cut over several applies, and ends as the same cut made at once.
TEST(Cut, ASplitBudgetSpreadsAStrokeOverAppliesAndEndsAtTheSameMesh) {
  Block whole, spread;
  spread.cut.set_max_cut_work_per_apply(40);
  for (Block* b : {&whole, &spread})
    for (int i = 0; i <= 120; ++i) b->cut.add_sample({0.003, -0.06 + 0.001 * i, -0.06}, Vec3::UnitZ(), true);
  whole.cut.apply(&whole.lat, &whole.vertices);
  int applies = 0;
  spread.cut.apply(&spread.lat, &spread.vertices);
  while (spread.cut.has_work()) {
    spread.cut.apply(&spread.lat, &spread.vertices);
    ++applies;
  }
  EXPECT_GT(applies, 2);
  EXPECT_EQ(spread.cut.triangles().size(), whole.cut.triangles().size());
  EXPECT_EQ(spread.lat.springs.size(), whole.lat.springs.size());
  EXPECT_EQ(triangle_components(spread.vertices.size(), spread.cut.triangles()), 2);
  EXPECT_EQ(mesh_problem(spread.cut.rest_vertices_m(), spread.cut.triangles()), "");
}

// A piece cut free falls onto the body, not through it: the top of the block, cut off along a slope, slides and
// rests on the body's cells: its surface stays within a cell of the body's top. Without the contact it falls to the floor.
TEST(Cut, APieceCutFreeRestsOnTheBodyAndNeverPassesThroughIt) {
  for (const bool contact : {true, false}) {
    Block b;
    b.spec.fix_floor = true;
    b.spec.gravity_m_per_s2 = Vec3(0, 0, -9.81);
    b.lat = build_lattice(b.box.grid, b.spec, region_cells(b.box.grid, kLevel, {1, 1, 1}, 8)).value();
    const BladeQuad slope{{-0.06, -0.06, 0.005}, {0.06, -0.06, 0.015}, {-0.06, 0.06, 0.005}, {0.06, 0.06, 0.015}};
    b.cut.apply_quads({slope}, &b.lat, &b.vertices);
    PieceContact pc;
    pc.update(b.lat, b.box.grid);
    ASSERT_GT(pc.free_nodes().size(), 0u);
    IntegratorWorkspace ws;
    const double floor_z = -kSide_m / 2;
    double lowest_mean = 1.0;  // the lowest the piece's nodes' mean height came
    for (int f = 0; f < 120; ++f) {
      step_lattice(&b.lat, IntegratorKind::kSymplecticEuler, 1.0 / 60.0, 256, {}, &ws);
      apply_floor(&b.lat, floor_z);
      if (contact) pc.apply(&b.lat, b.box.grid);
      double mean = 0.0;
      for (int32_t n : pc.free_nodes()) mean += b.lat.x_m[n].z();
      lowest_mean = std::min(lowest_mean, mean / static_cast<double>(pc.free_nodes().size()));
    }
    if (!contact) {
      EXPECT_LT(lowest_mean, floor_z + 0.015);  // the measure can fail: without contact the piece drops through
      continue;
    }
    // the piece's nodes start 2 and 4 cm above the body's top node plane (z = 0); landing on the soft body they
    // sink into it less than a cell on average (measured: 9 mm at worst, in the bounce), never through it
    EXPECT_GT(lowest_mean, -b.lat.cell_m);
    b.cut.deform(b.lat, &b.vertices);
    std::vector<int32_t> label;
    triangle_components(b.vertices.size(), b.cut.triangles(), &label);
    for (std::size_t t = 0; t < label.size(); ++t)
      for (int32_t v : b.cut.triangles()[t]) ASSERT_TRUE(b.vertices[v].allFinite());
    double lowest_v = 1.0;
    for (std::size_t v = 0; v < b.vertices.size(); ++v)
      if (b.cut.rest_vertices_m()[v].z() > 0.016) lowest_v = std::min(lowest_v, b.vertices[v].z());
    EXPECT_GT(lowest_v, 0.0 - b.lat.cell_m);
  }
}

}  // namespace
}  // namespace palpate
