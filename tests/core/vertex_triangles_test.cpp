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

}  // namespace
}  // namespace palpate
