// Bounds a cut keeps: the triangles it adds follow the trace over the edge length, each apply's work stays within
// its limit, and every vertex stays with its own piece (no spikes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/binding.h"
#include "sim/cut/cut_model.h"
#include "sim/sim_test_util.h"

namespace palpate {
namespace {

constexpr double kSide_m = 0.08;  // block from -0.04 to 0.04, level 3 cells of 2 cm
constexpr int kLevel = 3;

struct FineBlock {
  explicit FineBlock(int subdivisions) : box(test::make_box_model(kSide_m, 4, subdivisions)) {}
  test::BoxModel box;
  LatticeSpec spec = test::spec_for(kLevel, 40, 20, 10);
  Lattice lat = build_lattice(box.grid, spec, region_cells(box.grid, kLevel, {1, 1, 1}, 8)).value();
  CutModel cut{box.mesh, bind_vertices(box.grid, kLevel, box.mesh.vertices_m), &box.grid, kLevel, 0.2};
  std::vector<Vec3> vertices = box.mesh.vertices_m;
};

// The oblique plane n . x = c, as one quad reaching past the block on every side.
const Vec3 kNormal = Vec3(1.0, 0.35, 0.2).normalized();
constexpr double kOffset_m = 0.0047;
BladeQuad oblique_quad() {
  const Vec3 u = kNormal.cross(Vec3::UnitZ()).normalized(), v = kNormal.cross(u);
  const Vec3 c = kOffset_m * kNormal;
  return {c - 0.1 * u - 0.1 * v, c - 0.1 * u + 0.1 * v, c + 0.1 * u - 0.1 * v, c + 0.1 * u + 0.1 * v};
}

// Perimeter of the plane's section of the block: where it crosses the cube's twelve edges, in order around.
double section_perimeter_m() {
  const double h = kSide_m / 2;
  std::vector<Vec3> p;
  for (int axis = 0; axis < 3; ++axis)
    for (int a = -1; a <= 1; a += 2)
      for (int b = -1; b <= 1; b += 2) {
        Vec3 q = Vec3::Zero();
        q[(axis + 1) % 3] = a * h;
        q[(axis + 2) % 3] = b * h;
        // q + s e_axis on the plane
        const double s = (kOffset_m - kNormal.dot(q)) / kNormal[axis];
        if (std::abs(s) <= h) p.push_back(q + s * Vec3::Unit(axis));
      }
  Vec3 mid = Vec3::Zero();
  for (const Vec3& x : p) mid += x / static_cast<double>(p.size());
  const Vec3 u = kNormal.cross(Vec3::UnitZ()).normalized(), v = kNormal.cross(u);
  std::sort(p.begin(), p.end(), [&](const Vec3& a, const Vec3& b) {
    return std::atan2((a - mid).dot(v), (a - mid).dot(u)) < std::atan2((b - mid).dot(v), (b - mid).dot(u));
  });
  double len = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) len += (p[(i + 1) % p.size()] - p[i]).norm();
  return len;
}

// The stated bound: triangles_added <= 2 x triangles crossed, and on a mesh of edge h the triangles crossed along
// a trace of length L are at most kCrossedPerEdge L / h (a right-triangle grid: a line crosses at most two
// triangles per square it enters, and at most two squares per edge length it travels). So triangles_added <=
// 2 kCrossedPerEdge L / h, whatever the mesh's size. Refined twice as finely, the block has four times the
// triangles and the cut adds twice as many.
constexpr double kCrossedPerEdge = 4.0;

TEST(CutBounds, TrianglesAddedFollowTheTraceOverTheEdgeLength) {
  const double trace_m = section_perimeter_m();
  ASSERT_GT(trace_m, 4 * kSide_m * 0.9);  // the plane cuts the block through
  int added[2] = {0, 0};
  std::size_t triangles[2] = {0, 0};
  for (int r = 0; r < 2; ++r) {
    const int subdivisions = 8 << r;
    FineBlock b(subdivisions);
    triangles[r] = b.box.mesh.triangles.size();
    const CutReport rep = b.cut.apply_quads({oblique_quad()}, &b.lat, &b.vertices);
    const double h = kSide_m / subdivisions;
    const int crossed = rep.split.tris_one_cut + rep.split.tris_two_cut + rep.split.tris_three_cut;
    EXPECT_LE(rep.split.triangles_added, 2 * crossed);
    EXPECT_LE(crossed, kCrossedPerEdge * trace_m / h) << "subdivisions " << subdivisions;
    EXPECT_LE(rep.split.triangles_added, 2 * kCrossedPerEdge * trace_m / h);
    EXPECT_EQ(triangle_components(b.vertices.size(), b.cut.triangles()), 2);
    EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
    added[r] = rep.split.triangles_added;
  }
  EXPECT_EQ(triangles[1], 4 * triangles[0]);
  const double ratio = static_cast<double>(added[1]) / added[0];
  EXPECT_GT(ratio, 1.6);
  EXPECT_LT(ratio, 2.4);
}

// A stroke of many servo samples through a fine block under a work limit: every apply that cut more than one quad
// and more than the quarter of the queue the lag bound takes tested at most the limit's triangles and vertices, the binding tested only vertices near the blade, and the
// stroke ends cut through.
TEST(CutBounds, EveryApplysWorkStaysWithinTheLimit) {
  constexpr int kLimit = 400;
  FineBlock b(32);
  b.cut.set_max_cut_work_per_apply(kLimit);
  const Vec3 axis = Vec3(0.25, 0.1, 1.0).normalized();
  for (int i = 0; i <= 120; ++i) b.cut.add_sample({0.004, -0.06 + 0.001 * i, -0.06}, axis, true);
  int applies = 0, max_work = 0, max_vertices = 0;
  do {
    // what the lag bound alone takes: a quarter of the queue (known from the second apply on: the first maps the
    // whole stroke into the queue)
    const int quarter = static_cast<int>((b.cut.queued_quads() + 3) / 4);
    const CutReport rep = b.cut.apply(&b.lat, &b.vertices);
    ++applies;
    if (applies > 1 && rep.quads_cut > 1 && rep.quads_cut > quarter) {
      EXPECT_LE(rep.work(), kLimit) << "apply " << applies;
      max_vertices = std::max(max_vertices, rep.vertices_tested);
    }
    max_work = std::max(max_work, rep.work());
  } while (b.cut.has_work());
  EXPECT_GT(applies, 5);
  EXPECT_GT(max_vertices, 0);
  EXPECT_LT(max_vertices, static_cast<int>(b.box.mesh.vertices_m.size()) / 8);
  EXPECT_EQ(triangle_components(b.vertices.size(), b.cut.triangles()), 2);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
}

// A stroke that sweeps more a frame than the work limit lets through (a dense mesh: here a limit of one item) is
// still cut where the blade went, at most a few applies behind it: the queue stays within four frames' quads and is
// empty a few applies after the stroke ends, and the stroke ends cut through.
TEST(CutBounds, TheCutKeepsUpWithTheBladeWhateverTheLimit) {
  FineBlock b(32);
  b.cut.set_max_cut_work_per_apply(1);
  const Vec3 axis = Vec3(0.25, 0.1, 1.0).normalized();
  std::size_t most_queued = 0, per_frame = 0;
  int sample = 0;
  for (int frame = 0; frame < 12; ++frame) {
    for (int i = 0; i < 10; ++i, ++sample) b.cut.add_sample({0.004, -0.06 + 0.001 * sample, -0.06}, axis, true);
    const std::size_t before = b.cut.queued_quads();
    b.cut.apply(&b.lat, &b.vertices);
    per_frame = std::max(per_frame, b.cut.queued_quads() + b.cut.last_quads().size() - before);
    most_queued = std::max(most_queued, b.cut.queued_quads());
  }
  ASSERT_GT(per_frame, 8u);  // the stroke maps to more pieces a frame than the limit's one
  EXPECT_LE(most_queued, 4 * per_frame);
  b.cut.add_sample({0.004, -0.06 + 0.001 * sample, -0.06}, axis, true);
  int after = 0;
  while (b.cut.has_work() && after < 100) {
    b.cut.apply(&b.lat, &b.vertices);
    ++after;
  }
  // a quarter of what waits each apply: the queue empties in at most log(most queued) / log(4/3) applies, and two
  EXPECT_LE(after, static_cast<int>(std::ceil(std::log(static_cast<double>(most_queued)) / std::log(4.0 / 3.0))) + 2);
  EXPECT_EQ(triangle_components(b.vertices.size(), b.cut.triangles()), 2);
  EXPECT_EQ(mesh_problem(b.cut.rest_vertices_m(), b.cut.triangles()), "");
}

// No spikes: after a slanted stroke through the block, the +x piece's nodes are carried 3 cells away (up and
// aside) and the -x piece's stay; every vertex must land within a cell of where its own piece's motion takes it
// (the guarantee), and in fact exactly there (renormalised weights over its side's corners of a rigidly moved
// piece): a vertex that kept a corner across the cut would hang between the pieces.
TEST(CutBounds, NoVertexStraysFromItsPieceByMoreThanACell) {
  FineBlock b(12);
  const Vec3 axis = Vec3(0.3, 0.15, 1.0).normalized();
  for (int i = 0; i <= 120; ++i) b.cut.add_sample({0.002, -0.06 + 0.001 * i, -0.06}, axis, true);
  while (b.cut.has_work()) b.cut.apply(&b.lat, &b.vertices);
  std::vector<int32_t> node_piece;
  ASSERT_EQ(spring_components(b.lat, &node_piece), 2);
  std::vector<int32_t> tri_piece;
  ASSERT_EQ(triangle_components(b.vertices.size(), b.cut.triangles(), &tri_piece), 2);
  // the +x pieces: those of the node and the triangle farthest along +x
  auto far_node = std::max_element(b.lat.rest_m.begin(), b.lat.rest_m.end(),
                                   [](const Vec3& p, const Vec3& q) { return p.x() < q.x(); }) - b.lat.rest_m.begin();
  const Vec3 move = 3.0 * b.lat.cell_m * Vec3(0.3, 0.2, 1.0).normalized();
  for (std::size_t i = 0; i < b.lat.num_nodes(); ++i)
    if (node_piece[i] == node_piece[far_node]) b.lat.x_m[i] = b.lat.rest_m[i] + move;
  std::vector<int32_t> vertex_piece(b.vertices.size(), -1);
  for (std::size_t t = 0; t < tri_piece.size(); ++t)
    for (int32_t v : b.cut.triangles()[t]) vertex_piece[v] = tri_piece[t];
  int32_t plus = -1;
  double far_x = -1.0;
  for (std::size_t v = 0; v < b.vertices.size(); ++v)
    if (b.cut.rest_vertices_m()[v].x() > far_x) far_x = b.cut.rest_vertices_m()[v].x(), plus = vertex_piece[v];
  b.cut.deform(b.lat, &b.vertices);
  double worst_m = 0.0;
  int off = 0;
  for (std::size_t v = 0; v < b.vertices.size(); ++v) {
    if (vertex_piece[v] < 0) continue;
    const Vec3 expect = b.cut.rest_vertices_m()[v] + (vertex_piece[v] == plus ? move : Vec3::Zero());
    const double d = (b.vertices[v] - expect).norm();
    worst_m = std::max(worst_m, d);
    off += d > 1e-9;
  }
  EXPECT_LE(worst_m, b.lat.cell_m);
  EXPECT_EQ(off, 0) << "worst " << worst_m / b.lat.cell_m << " cells";
}

}  // namespace
}  // namespace palpate
