// Normals of a few moved vertices, recomputed alone, equal the whole mesh's recomputation bit for bit.
#include "core/vertex_triangles.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "core/mesh_io.h"
#include "core/tri_mesh.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

TriMesh bunny() { return load_mesh(test::source_path("scenes/bunny.obj")).value(); }

TEST(VertexTriangles, RowsListEachCornerInTriangleOrder) {
  // triangle 1 repeats vertex 2: it is listed twice in vertex 2's row
  const std::vector<std::array<int32_t, 3>> tris = {{0, 1, 2}, {2, 2, 3}, {3, 1, 0}};
  const auto a = VertexTriangles::build(5, tris);
  ASSERT_EQ(a.num_vertices(), 5u);
  auto row = [&](int v) { return std::vector<int32_t>(a.triangles.begin() + a.offsets[v], a.triangles.begin() + a.offsets[v + 1]); };
  EXPECT_EQ(row(0), (std::vector<int32_t>{0, 2}));
  EXPECT_EQ(row(1), (std::vector<int32_t>{0, 2}));
  EXPECT_EQ(row(2), (std::vector<int32_t>{0, 1, 1}));
  EXPECT_EQ(row(3), (std::vector<int32_t>{1, 2}));
  EXPECT_TRUE(row(4).empty());
}

TEST(VertexTriangles, MovedVerticesGetTheWholeMeshNormalsBitForBit) {
  TriMesh m = bunny();
  const auto adj = VertexTriangles::build(m.vertices_m.size(), m.triangles);
  std::vector<Vec3> normals;
  compute_vertex_normals(m.vertices_m, m.triangles, &normals);
  // move every vertex in a slab by a smooth, non-affine field
  std::vector<int32_t> moving;
  double lo = m.vertices_m[0].z(), hi = lo;
  for (const Vec3& p : m.vertices_m) lo = std::min(lo, p.z()), hi = std::max(hi, p.z());
  const double s = hi - lo;
  for (std::size_t v = 0; v < m.vertices_m.size(); ++v) {
    Vec3& p = m.vertices_m[v];
    if (p.z() > lo + 0.4 * s && p.z() < lo + 0.5 * s) {
      p += s * Vec3(0.03 * std::sin(40 * p.y() / s), 0.02 * p.x() * p.x() / (s * s), -0.04 * std::cos(30 * p.x() / s));
      moving.push_back(static_cast<int32_t>(v));
    }
  }
  ASSERT_GT(moving.size(), 20u);
  ASSERT_LT(moving.size(), m.vertices_m.size() / 2);
  std::vector<uint8_t> mark;
  std::vector<int32_t> deps;
  normal_dependents(m.triangles, adj, moving, &mark, &deps);
  update_vertex_normals(m.vertices_m, m.triangles, adj, deps, &normals);
  std::vector<Vec3> full;
  compute_vertex_normals(m.vertices_m, m.triangles, &full);
  int64_t differ = 0;
  for (std::size_t v = 0; v < full.size(); ++v) differ += (full[v].array() != normals[v].array()).any() ? 1 : 0;
  EXPECT_EQ(differ, 0);
  EXPECT_TRUE(std::all_of(mark.begin(), mark.end(), [](uint8_t b) { return b == 0; }));
}

// The patch computes each face normal once and sums per vertex: the whole mesh's normals bit for bit, frame after
// frame, and nothing outside its vertices is written.
TEST(VertexTriangles, NormalPatchGivesTheWholeMeshNormalsBitForBit) {
  TriMesh m = subdivide_midpoint(bunny());
  const std::vector<Vec3> rest = m.vertices_m;
  const auto adj = VertexTriangles::build(m.vertices_m.size(), m.triangles);
  std::vector<Vec3> normals;
  compute_vertex_normals(m.vertices_m, m.triangles, &normals);
  std::vector<int32_t> moving;
  for (std::size_t v = 0; v < rest.size(); ++v)
    if (rest[v].x() > rest[0].x()) moving.push_back(static_cast<int32_t>(v));
  ASSERT_GT(moving.size(), 100u);
  std::vector<uint8_t> mark;
  std::vector<int32_t> deps;
  normal_dependents(m.triangles, adj, moving, &mark, &deps);
  VertexNormalPatch patch;
  patch.attach(adj, deps);
  EXPECT_EQ(patch.vertex_ids(), deps);
  EXPECT_LT(patch.num_triangles(), m.triangles.size());
  const Vec3 marker(7.0, 7.0, 7.0);  // on the normals no patch vertex owns: must survive
  std::vector<uint8_t> in_patch(rest.size(), 0);
  for (int32_t v : deps) in_patch[v] = 1;
  for (std::size_t v = 0; v < rest.size(); ++v)
    if (!in_patch[v]) normals[v] = marker;
  for (int frame = 1; frame <= 3; ++frame) {
    for (int32_t v : moving) {
      const Vec3& r = rest[v];
      m.vertices_m[v] = r + frame * Vec3(0.002 * std::sin(90 * r.y()), 0.001 * std::cos(70 * r.z()), 0.0015 * r.x());
    }
    patch.update(m.vertices_m, m.triangles, &normals);
    std::vector<Vec3> full;
    compute_vertex_normals(m.vertices_m, m.triangles, &full);
    int64_t differ = 0, kept = 0;
    for (std::size_t v = 0; v < full.size(); ++v) {
      if (in_patch[v]) differ += (full[v].array() != normals[v].array()).any() ? 1 : 0;
      else kept += normals[v] == marker ? 1 : 0;
    }
    EXPECT_EQ(differ, 0) << "frame " << frame;
    EXPECT_EQ(kept, static_cast<int64_t>(rest.size() - deps.size())) << "frame " << frame;
  }
}

TEST(VertexTriangles, DependentsAreTheVerticesOfTrianglesWithAMovingVertex) {
  const TriMesh m = bunny();
  const auto adj = VertexTriangles::build(m.vertices_m.size(), m.triangles);
  const std::vector<int32_t> moving = {5, 17, 400, 1201};
  std::vector<uint8_t> mark;
  std::vector<int32_t> deps;
  normal_dependents(m.triangles, adj, moving, &mark, &deps);
  // brute force over every triangle
  std::set<int32_t> expect;
  for (const auto& t : m.triangles)
    for (int32_t mv : moving)
      if (t[0] == mv || t[1] == mv || t[2] == mv) expect.insert(t.begin(), t.end());
  EXPECT_EQ(deps, std::vector<int32_t>(expect.begin(), expect.end()));
}

TEST(VertexTriangles, CreaseNormalsKeepSharpEdgesAndSmoothShallowOnes) {
  // a roof: two faces meeting at a ridge along x, each turned `turn` degrees from +z, each of two triangles
  for (double turn : {10.0, 50.0}) {
    const double t = turn * 3.14159265358979323846 / 180.0;
    const std::vector<Vec3> v = {{0, 0, 0}, {1, 0, 0}, {0, -1, -std::tan(t)}, {1, -1, -std::tan(t)},
                                 {0, 1, -std::tan(t)}, {1, 1, -std::tan(t)}};
    const std::vector<std::array<int32_t, 3>> tris = {{0, 2, 3}, {0, 3, 1}, {0, 1, 5}, {0, 5, 4}};
    const auto adj = VertexTriangles::build(v.size(), tris);
    const Vec3 left = (v[2] - v[0]).cross(v[3] - v[0]).normalized();
    // with a crease of 60 degrees the ridge's corners of a face see both faces when they turn 2 x 10 degrees
    // (normal +z, the ridge smooth), only their own at 2 x 50 (the face's normal: the ridge stays sharp)
    const Vec3 n = crease_normal(v, v, tris, adj, 0, 0, std::cos(60.0 * 3.14159265358979323846 / 180.0));
    if (turn < 30.0) {
      EXPECT_NEAR(n.dot(Vec3::UnitZ()), 1.0, 1e-12);
    } else {
      EXPECT_NEAR(n.dot(left), 1.0, 1e-12);
    }
    // a corner off the ridge has only its own face's triangles
    EXPECT_NEAR(crease_normal(v, v, tris, adj, 0, 1, 0.5).dot(left), 1.0, 1e-12);
    // any turn counted (cos -1): the vertex normal, bit for bit
    const int32_t ids[] = {adj.triangles[adj.offsets[0]], adj.triangles[adj.offsets[0] + 1],
                           adj.triangles[adj.offsets[0] + 2], adj.triangles[adj.offsets[0] + 3]};
    EXPECT_EQ(crease_normal(v, v, tris, adj, 0, 0, -1.0), vertex_normal(v, tris, ids, 4));
    // a press that folds the shallow roof to 2 x 50 degrees makes no crease: the rest shape says which faces are one
    if (turn < 30.0) {
      std::vector<Vec3> pressed = v;
      for (int k : {2, 3, 4, 5}) pressed[k].z() = -std::tan(50.0 * 3.14159265358979323846 / 180.0);
      EXPECT_NEAR(crease_normal(pressed, v, tris, adj, 0, 0, 0.5).dot(Vec3::UnitZ()), 1.0, 1e-12);
    }
  }
}

}  // namespace
}  // namespace palpate
