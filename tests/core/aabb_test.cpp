#include "core/aabb.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "core/mesh_io.h"

namespace palpate {
namespace {

const std::string kBunnyPath = PALPATE_SOURCE_DIR "/scenes/bunny.obj";

TriMesh tetrahedron() {
  TriMesh m;
  m.vertices_m = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

void expect_error(const Result<Normalization>& r, const std::string& substring) {
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message.rfind("mesh 'm': ", 0), 0u) << r.error().message;
  EXPECT_NE(r.error().message.find(substring), std::string::npos) << r.error().message;
}

TEST(Aabb, OfExtentCenterContains) {
  const Aabb box = Aabb::of({Vec3(1, -2, 3), Vec3(-1, 4, 3.5), Vec3(0, 0, 5)});
  EXPECT_EQ(box.min_m, Vec3(-1, -2, 3));
  EXPECT_EQ(box.max_m, Vec3(1, 4, 5));
  EXPECT_EQ(box.extent(), Vec3(2, 6, 2));
  EXPECT_EQ(box.center(), Vec3(0, 1, 4));
  EXPECT_TRUE(box.contains(Vec3(1, 4, 5)));   // faces belong to the box
  EXPECT_TRUE(box.contains(Vec3(0, 0, 4)));
  EXPECT_FALSE(box.contains(Vec3(1.0001, 0, 4)));
  EXPECT_FALSE(box.contains(Vec3(0, std::nan(""), 4)));
}

TEST(Aabb, OfNothingIsEmpty) {
  const Aabb box = Aabb::of({});
  EXPECT_FALSE(box.contains(Vec3::Zero()));
  EXPECT_TRUE((box.extent().array() < 0).all());
}

TEST(NormalizeMesh, BunnyFillsCube) {
  auto loaded = load_mesh(kBunnyPath);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  TriMesh mesh = loaded.value();
  ASSERT_EQ(mesh.num_vertices(), 1839u);
  ASSERT_EQ(mesh.num_triangles(), 3674u);
  const TriMesh raw = mesh;
  const double size_m = 0.12;
  const auto r = normalize_mesh(&mesh, size_m, "bunny");
  ASSERT_TRUE(r.ok()) << r.error().message;
  const Normalization& n = r.value();
  EXPECT_EQ(mesh.num_vertices(), 1839u);
  EXPECT_EQ(mesh.num_triangles(), 3674u);
  const Aabb box = Aabb::of(mesh.vertices_m);
  EXPECT_EQ(box.extent().maxCoeff(), size_m);
  EXPECT_NEAR(box.center().norm(), 0.0, 1e-15);
  EXPECT_EQ(n.cube.min_m, Vec3::Constant(-0.06));
  EXPECT_EQ(n.cube.max_m, Vec3::Constant(0.06));
  for (std::size_t v = 0; v < mesh.num_vertices(); ++v) {
    EXPECT_TRUE(n.cube.contains(mesh.vertices_m[v])) << v;
    EXPECT_NEAR((n.scale * raw.vertices_m[v] + n.offset_m - mesh.vertices_m[v]).norm(), 0.0, 1e-15) << v;
  }
}

TEST(NormalizeMesh, ScaleAndOffsetOfKnownBox) {
  TriMesh mesh = tetrahedron();
  for (Vec3& v : mesh.vertices_m) v = Vec3(4.0 * v.x() + 10.0, 2.0 * v.y() - 3.0, v.z());
  const auto r = normalize_mesh(&mesh, 2.0, "m");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_DOUBLE_EQ(r.value().scale, 0.5);
  EXPECT_TRUE(r.value().offset_m.isApprox(Vec3(-6.0, 1.0, -0.25)));
  EXPECT_EQ(Aabb::of(mesh.vertices_m).min_m.x(), -1.0);
  EXPECT_EQ(Aabb::of(mesh.vertices_m).max_m.x(), 1.0);
}

TEST(NormalizeMesh, NoVertices) {
  TriMesh mesh;
  expect_error(normalize_mesh(&mesh, 1.0, "m"), "no vertices");
}

TEST(NormalizeMesh, NoTriangles) {
  TriMesh mesh = tetrahedron();
  mesh.triangles.clear();
  expect_error(normalize_mesh(&mesh, 1.0, "m"), "no triangles");
}

TEST(NormalizeMesh, AllVerticesAtOnePoint) {
  TriMesh mesh = tetrahedron();
  for (Vec3& v : mesh.vertices_m) v = Vec3(3, 4, 5);
  expect_error(normalize_mesh(&mesh, 1.0, "m"), "all vertices at one point");
}

TEST(NormalizeMesh, FlatOnZ) {
  TriMesh mesh = tetrahedron();
  mesh.vertices_m[3] = Vec3(1, 1, 0);
  const TriMesh before = mesh;
  expect_error(normalize_mesh(&mesh, 1.0, "m"), "flat on axis z (extent 0 of 1)");
  EXPECT_EQ(mesh.vertices_m, before.vertices_m);  // untouched on error
}

TEST(NormalizeMesh, FlatOnXBelowRelativeThreshold) {
  TriMesh mesh = tetrahedron();
  for (Vec3& v : mesh.vertices_m) v.x() *= 1e-7;
  expect_error(normalize_mesh(&mesh, 1.0, "m"), "flat on axis x (extent 1e-07 of 1)");
}

TEST(NormalizeMesh, NonFiniteVertex) {
  TriMesh mesh = tetrahedron();
  mesh.vertices_m[2].y() = std::numeric_limits<double>::infinity();
  expect_error(normalize_mesh(&mesh, 1.0, "m"), "vertex 2 is not finite");
  mesh.vertices_m[2].y() = std::nan("");
  expect_error(normalize_mesh(&mesh, 1.0, "m"), "vertex 2 is not finite");
}

TEST(NormalizeMesh, TriangleIndexOutOfRange) {
  TriMesh mesh = tetrahedron();
  mesh.triangles[1][2] = 40;
  expect_error(normalize_mesh(&mesh, 1.0, "m"), "triangle 1 vertex index 40 is beyond the vertex list (size 4)");
}

TEST(NormalizeMesh, BadSize) {
  TriMesh mesh = tetrahedron();
  expect_error(normalize_mesh(&mesh, 0.0, "m"), "size 0 is not a positive finite number");
  expect_error(normalize_mesh(&mesh, std::nan(""), "m"), "is not a positive finite number");
}

}  // namespace
}  // namespace palpate

namespace palpate {
namespace {

TEST(TriMesh, MidpointSubdivisionCountsAndKeepsTheSurface) {
  const TriMesh box = make_box_mesh(Vec3(1, 2, 3), 2);  // closed: edges = 3 t / 2
  const TriMesh sub = subdivide_midpoint(box);
  EXPECT_EQ(sub.num_triangles(), 4 * box.num_triangles());
  EXPECT_EQ(sub.num_vertices(), box.num_vertices() + 3 * box.num_triangles() / 2);
  // flat faces stay flat: total area and the box are unchanged
  auto area = [](const TriMesh& m) {
    double a = 0;
    for (const auto& t : m.triangles)
      a += 0.5 * (m.vertices_m[t[1]] - m.vertices_m[t[0]]).cross(m.vertices_m[t[2]] - m.vertices_m[t[0]]).norm();
    return a;
  };
  EXPECT_NEAR(area(sub), area(box), 1e-12);
  EXPECT_NEAR(area(box), 2 * (1 * 2 + 2 * 3 + 1 * 3), 1e-12);
}

}  // namespace
}  // namespace palpate
