#include "core/binding.h"

#include <gtest/gtest.h>

#include <string>

#include "core/aabb.h"
#include "core/mesh_io.h"

namespace palpate {
namespace {

const std::string kBunnyPath = PALPATE_SOURCE_DIR "/scenes/bunny.obj";

void expect_bound_inside(const GridHierarchy& grid, int level, const Vec3& p, const VertexBinding& b) {
  ASSERT_GE(b.cell, 0);
  ASSERT_LT(b.cell, grid.num_cells(level));
  EXPECT_TRUE((b.local.array() >= 0.0).all() && (b.local.array() <= 1.0).all()) << b.local.transpose();
  const Vec3 base_m = grid.cell_min_m(grid.coord_of(b.cell, level), level);
  // eq. (9) inverts eq. (1)
  EXPECT_LE((base_m + b.local * grid.cell_size_m(level) - p).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Binding, EveryBunnyVertexInsideItsCellAtEveryLevel) {
  auto loaded = load_mesh(kBunnyPath);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  TriMesh mesh = loaded.value();
  const auto norm = normalize_mesh(&mesh, 0.1, "bunny");
  ASSERT_TRUE(norm.ok()) << norm.error().message;
  auto built = GridHierarchy::build(mesh, norm.value().cube, 6);
  ASSERT_TRUE(built.ok()) << built.error().message;
  const GridHierarchy& grid = built.value();
  for (int level = 1; level <= grid.levels(); ++level) {
    const std::vector<VertexBinding> bindings = bind_vertices(grid, level, mesh.vertices_m);
    ASSERT_EQ(bindings.size(), mesh.num_vertices());
    for (std::size_t v = 0; v < bindings.size(); ++v) {
      expect_bound_inside(grid, level, mesh.vertices_m[v], bindings[v]);
      EXPECT_EQ(bindings[v].cell, grid.linear_index(grid.cell_of(mesh.vertices_m[v], level), level));
      // a vertex's cell is the ancestor of its leaf
      int32_t cell = grid.linear_index(grid.cell_of(mesh.vertices_m[v], grid.levels()), grid.levels());
      for (int l = grid.levels(); l > level; --l) cell = grid.parent(cell, l);
      EXPECT_EQ(bindings[v].cell, cell);
    }
  }
}

TEST(Binding, MaxFaceGoesToLastCellWithLocalOne) {
  const TriMesh box = make_box_mesh(Vec3::Constant(1.0), 2);
  const Aabb cube{Vec3::Constant(-0.5), Vec3::Constant(0.5)};
  auto built = GridHierarchy::build(box, cube, 4);
  ASSERT_TRUE(built.ok()) << built.error().message;
  const GridHierarchy& grid = built.value();
  const VertexBinding top = bind_point(grid, 4, Vec3::Constant(0.5));
  EXPECT_EQ(top.cell, grid.num_cells(4) - 1);
  EXPECT_EQ(top.local, Vec3::Ones());
  const VertexBinding bottom = bind_point(grid, 4, Vec3::Constant(-0.5));
  EXPECT_EQ(bottom.cell, 0);
  EXPECT_EQ(bottom.local, Vec3::Zero());
  const VertexBinding mixed = bind_point(grid, 3, Vec3(0.5, -0.5, 0.0625));
  EXPECT_EQ(mixed.cell, grid.linear_index({3, 0, 2}, 3));
  EXPECT_EQ(mixed.local, Vec3(1.0, 0.0, 0.25));
  // every box vertex, many of them on the max faces
  for (int level = 1; level <= 4; ++level) {
    for (const Vec3& p : box.vertices_m) expect_bound_inside(grid, level, p, bind_point(grid, level, p));
  }
}

TEST(Binding, PointsOutsideTheCubeAreClamped) {
  const TriMesh box = make_box_mesh(Vec3::Constant(0.5), 1);
  auto built = GridHierarchy::build(box, Aabb{Vec3::Constant(-0.5), Vec3::Constant(0.5)}, 3);
  ASSERT_TRUE(built.ok()) << built.error().message;
  const VertexBinding b = bind_point(built.value(), 3, Vec3(2.0, -2.0, 0.1));
  EXPECT_EQ(b.cell, built.value().linear_index({3, 0, 2}, 3));
  EXPECT_EQ(b.local.x(), 1.0);
  EXPECT_EQ(b.local.y(), 0.0);
  EXPECT_NEAR(b.local.z(), 0.4, 1e-12);
}

}  // namespace
}  // namespace palpate
