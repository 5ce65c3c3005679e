#include "core/grid_hierarchy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "core/aabb.h"
#include "core/mesh_io.h"

namespace palpate {
namespace {

const std::string kBunnyPath = PALPATE_SOURCE_DIR "/scenes/bunny.obj";
const Aabb kUnitCube{Vec3::Constant(-0.5), Vec3::Constant(0.5)};

// the bunny scaled into the unit cube centred at the origin
TriMesh normalized_bunny() {
  auto loaded = load_mesh(kBunnyPath);
  EXPECT_TRUE(loaded.ok()) << loaded.error().message;
  TriMesh mesh = loaded.value();
  const auto norm = normalize_mesh(&mesh, 1.0, "bunny");
  EXPECT_TRUE(norm.ok()) << norm.error().message;
  return mesh;
}

GridHierarchy build_or_die(const TriMesh& mesh, const Aabb& cube, int levels) {
  auto r = GridHierarchy::build(mesh, cube, levels);
  EXPECT_TRUE(r.ok()) << r.error().message;
  return std::move(r).value();
}

bool contains(std::span<const int32_t> ids, int32_t id) {
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}

TEST(GridHierarchy, CellCountsAndSizesPerLevel) {
  const GridHierarchy grid = build_or_die(make_box_mesh(Vec3::Constant(0.5), 2), kUnitCube, 5);
  EXPECT_EQ(grid.levels(), 5);
  const int64_t expected_cells[5] = {1, 8, 64, 512, 4096};
  for (int level = 1; level <= 5; ++level) {
    EXPECT_EQ(grid.cells_per_axis(level), 1 << (level - 1));
    EXPECT_EQ(grid.num_cells(level), expected_cells[level - 1]);
    EXPECT_DOUBLE_EQ(grid.cell_size_m(level), 1.0 / (1 << (level - 1)));
  }
  EXPECT_EQ(grid.num_vertices(), 26u);
  EXPECT_EQ(grid.num_triangles(), 48u);
}

TEST(GridHierarchy, DefaultIsAnEmptyOneLevelGrid) {
  const GridHierarchy grid;
  EXPECT_EQ(grid.levels(), 1);
  EXPECT_EQ(grid.num_cells(1), 1);
  EXPECT_EQ(grid.num_vertices(), 0u);
  EXPECT_TRUE(grid.leaf_vertices(0).empty());
  EXPECT_TRUE(grid.leaf_triangles(0).empty());
  EXPECT_FALSE(grid.surface_cell(0, 1));
  EXPECT_FALSE(grid.solid_cell(0, 1));
  std::vector<int32_t> near{7};
  grid.triangles_near(Vec3::Constant(-1), Vec3::Constant(1), &near);
  EXPECT_TRUE(near.empty());
}

TEST(GridHierarchy, LevelsOutOfRange) {
  const TriMesh box = make_box_mesh(Vec3::Constant(0.5), 1);
  for (int levels : {0, 9, -1}) {
    const auto r = GridHierarchy::build(box, kUnitCube, levels);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message, "grid levels " + std::to_string(levels) + " out of range [1, 8]");
  }
  EXPECT_TRUE(GridHierarchy::build(box, kUnitCube, GridHierarchy::kMaxLevels).ok());
}

TEST(GridHierarchy, RejectsVertexOutsideCubeAndNonCube) {
  TriMesh box = make_box_mesh(Vec3::Constant(0.5), 1);
  const auto flat = GridHierarchy::build(box, Aabb{Vec3(-1, -1, -1), Vec3(1, 1, 2)}, 3);
  ASSERT_FALSE(flat.ok());
  EXPECT_NE(flat.error().message.find("is not a cube"), std::string::npos) << flat.error().message;
  box.vertices_m[3].x() = 0.6;
  const auto outside = GridHierarchy::build(box, kUnitCube, 3);
  ASSERT_FALSE(outside.ok());
  EXPECT_NE(outside.error().message.find("vertex 3 at (0.6"), std::string::npos) << outside.error().message;
  EXPECT_NE(outside.error().message.find("outside the cube"), std::string::npos) << outside.error().message;
  box = make_box_mesh(Vec3::Constant(0.5), 1);
  box.triangles[2][0] = -1;
  const auto bad_index = GridHierarchy::build(box, kUnitCube, 3);
  ASSERT_FALSE(bad_index.ok());
  EXPECT_NE(bad_index.error().message.find("triangle 2 vertex index -1"), std::string::npos);
}

TEST(GridHierarchy, IndexRoundTripsParentsAndChildren) {
  const GridHierarchy grid = build_or_die(make_box_mesh(Vec3::Constant(0.5), 1), kUnitCube, 5);
  for (int level = 1; level <= 5; ++level) {
    std::set<int32_t> seen_children;
    for (int32_t c = 0; c < grid.num_cells(level); ++c) {
      const CellCoord coord = grid.coord_of(c, level);
      EXPECT_EQ(grid.linear_index(coord, level), c);
      const int n = grid.cells_per_axis(level);
      EXPECT_EQ(c, coord.i + n * (coord.j + n * coord.k));
      if (level >= 2) {
        const int32_t p = grid.parent(c, level);
        EXPECT_TRUE(contains(grid.children(p, level - 1), c));
      }
      if (level < 5) {
        for (int32_t child : grid.children(c, level)) {
          EXPECT_EQ(grid.parent(child, level + 1), c);
          EXPECT_TRUE(seen_children.insert(child).second) << "child listed twice";
          // a child's cube lies inside its parent's
          const Vec3 lo = grid.cell_min_m(grid.coord_of(child, level + 1), level + 1);
          const Vec3 parent_lo = grid.cell_min_m(coord, level);
          EXPECT_TRUE((lo.array() >= parent_lo.array()).all());
          EXPECT_TRUE((lo.array() < parent_lo.array() + grid.cell_size_m(level)).all());
        }
      }
    }
    if (level < 5) {
      EXPECT_EQ(static_cast<int64_t>(seen_children.size()), grid.num_cells(level + 1));
    }
  }
}

TEST(GridHierarchy, CellOfClampsAndPutsMaxFaceInLastCell) {
  const GridHierarchy grid = build_or_die(make_box_mesh(Vec3::Constant(0.5), 1), kUnitCube, 4);
  const CellCoord last = grid.cell_of(Vec3::Constant(0.5), 4);
  EXPECT_EQ(last.i, 7);
  EXPECT_EQ(last.j, 7);
  EXPECT_EQ(last.k, 7);
  const CellCoord first = grid.cell_of(Vec3::Constant(-0.5), 4);
  EXPECT_EQ(grid.linear_index(first, 4), 0);
  const CellCoord far = grid.cell_of(Vec3(9, -9, 0.01), 4);
  EXPECT_EQ(far.i, 7);
  EXPECT_EQ(far.j, 0);
  EXPECT_EQ(far.k, 4);
  EXPECT_EQ(grid.cell_min_m({1, 2, 3}, 4), Vec3(-0.375, -0.25, -0.125));
}

TEST(GridHierarchy, LeafVerticesPartitionAllVertices) {
  const TriMesh mesh = normalized_bunny();
  const GridHierarchy grid = build_or_die(mesh, kUnitCube, 6);
  std::vector<int> times_listed(mesh.num_vertices(), 0);
  for (int32_t leaf = 0; leaf < grid.num_cells(6); ++leaf) {
    const auto ids = grid.leaf_vertices(leaf);
    EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
    for (int32_t v : ids) {
      ++times_listed[v];
      EXPECT_EQ(grid.linear_index(grid.cell_of(mesh.vertices_m[v], 6), 6), leaf);
    }
  }
  for (std::size_t v = 0; v < mesh.num_vertices(); ++v) EXPECT_EQ(times_listed[v], 1) << "vertex " << v;
}

TEST(GridHierarchy, LeafTrianglesCoverTheirVerticesAndInteriorPoints) {
  const TriMesh mesh = normalized_bunny();
  const int levels = 6;
  const GridHierarchy grid = build_or_die(mesh, kUnitCube, levels);
  const double cell_m = grid.cell_size_m(levels);
  for (std::size_t t = 0; t < mesh.num_triangles(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (int32_t v : tri) {
      const int32_t leaf = grid.linear_index(grid.cell_of(mesh.vertices_m[v], levels), levels);
      EXPECT_TRUE(contains(grid.leaf_triangles(leaf), static_cast<int32_t>(t))) << "triangle " << t;
    }
    // sample points of the triangle: their leaves must list it
    for (int a = 0; a <= 8; ++a) {
      for (int b = 0; a + b <= 8; ++b) {
        const Vec3 p = (a * mesh.vertices_m[tri[0]] + b * mesh.vertices_m[tri[1]] +
                        (8 - a - b) * mesh.vertices_m[tri[2]]) / 8.0;
        const int32_t leaf = grid.linear_index(grid.cell_of(p, levels), levels);
        EXPECT_TRUE(contains(grid.leaf_triangles(leaf), static_cast<int32_t>(t))) << "triangle " << t;
      }
    }
  }
  // no leaf lists a triangle whose bounding box misses it
  for (int32_t leaf = 0; leaf < grid.num_cells(levels); ++leaf) {
    const Vec3 lo = grid.cell_min_m(grid.coord_of(leaf, levels), levels);
    const auto ids = grid.leaf_triangles(leaf);
    EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
    for (int32_t t : ids) {
      const Aabb tb = Aabb::of({mesh.vertices_m[mesh.triangles[t][0]], mesh.vertices_m[mesh.triangles[t][1]],
                                mesh.vertices_m[mesh.triangles[t][2]]});
      EXPECT_TRUE((tb.max_m.array() >= lo.array() - 1e-9).all() &&
                  (tb.min_m.array() <= lo.array() + cell_m + 1e-9).all());
    }
  }
}

TEST(GridHierarchy, LeafTrianglesRejectBoxesOffTheTrianglePlane) {
  // one big triangle x + y + z = 0.2 (clipped to the cube): its bounding box covers the whole grid but only
  // cells the plane crosses may list it
  TriMesh mesh;
  mesh.vertices_m = {Vec3(0.5, 0.2, -0.5), Vec3(-0.5, 0.5, 0.2), Vec3(0.2, -0.5, 0.5)};
  mesh.triangles = {{0, 1, 2}};
  const GridHierarchy grid = build_or_die(mesh, kUnitCube, 4);
  const double h_m = 0.5 * grid.cell_size_m(4);
  int listed = 0;
  for (int32_t leaf = 0; leaf < grid.num_cells(4); ++leaf) {
    const Vec3 center_m = grid.cell_min_m(grid.coord_of(leaf, 4), 4) + Vec3::Constant(h_m);
    const double plane_distance = std::abs(center_m.sum() - 0.2) / std::sqrt(3.0);
    if (!grid.leaf_triangles(leaf).empty()) {
      ++listed;
      EXPECT_LE(plane_distance, h_m * std::sqrt(3.0) + 1e-12) << leaf;
    }
  }
  EXPECT_GT(listed, 0);
  EXPECT_LT(listed, grid.num_cells(4) / 2);
}

TEST(GridHierarchy, SurfaceFlagsAreTheOrOfChildren) {
  const TriMesh mesh = normalized_bunny();
  const GridHierarchy grid = build_or_die(mesh, kUnitCube, 5);
  for (int level = 1; level < 5; ++level) {
    int64_t count = 0;
    for (int32_t c = 0; c < grid.num_cells(level); ++c) {
      bool any = false;
      for (int32_t child : grid.children(c, level)) any = any || grid.surface_cell(child, level + 1);
      EXPECT_EQ(grid.surface_cell(c, level), any);
      count += grid.surface_cell(c, level);
      if (grid.surface_cell(c, level)) {
        EXPECT_TRUE(grid.solid_cell(c, level));
      }
    }
    EXPECT_EQ(grid.surface_cells(level), count);
  }
  EXPECT_TRUE(grid.surface_cell(0, 1));
  EXPECT_EQ(grid.solid_cells(1), 1);
  // the bunny is closed enough that some leaves are enclosed without touching the surface
  EXPECT_GT(grid.solid_cells(5), grid.surface_cells(5));
}

TEST(GridHierarchy, SolidCellsOfACentredBox) {
  // box faces at +-0.275 fall inside leaf layers 1 and 6 of 8
  const GridHierarchy grid = build_or_die(make_box_mesh(Vec3::Constant(0.55), 3), kUnitCube, 4);
  auto in = [](int v, int lo, int hi) { return v >= lo && v <= hi; };
  int64_t solid = 0;
  for (int32_t c = 0; c < grid.num_cells(4); ++c) {
    const CellCoord cc = grid.coord_of(c, 4);
    const bool interior = in(cc.i, 2, 5) && in(cc.j, 2, 5) && in(cc.k, 2, 5);
    const bool shell_or_inside = in(cc.i, 1, 6) && in(cc.j, 1, 6) && in(cc.k, 1, 6);
    EXPECT_EQ(grid.solid_cell(c, 4), shell_or_inside) << c;
    EXPECT_EQ(grid.surface_cell(c, 4), shell_or_inside && !interior) << c;
    solid += grid.solid_cell(c, 4);
  }
  EXPECT_EQ(solid, 6 * 6 * 6);
  EXPECT_EQ(grid.solid_cells(4), 216);
  EXPECT_EQ(grid.surface_cells(4), 216 - 64);
  EXPECT_FALSE(grid.solid_cell(grid.linear_index({0, 0, 0}, 4), 4));
  EXPECT_FALSE(grid.solid_cell(grid.linear_index({7, 7, 7}, 4), 4));
  EXPECT_TRUE(grid.solid_cell(grid.linear_index({3, 4, 3}, 4), 4));
}

TEST(GridHierarchy, SolidCellsOfAGridAlignedBox) {
  // faces exactly on grid planes +-0.25: the triangles touch the cells on both sides of each plane
  const GridHierarchy grid = build_or_die(make_box_mesh(Vec3::Constant(0.5), 2), kUnitCube, 4);
  for (int32_t c = 0; c < grid.num_cells(4); ++c) {
    const CellCoord cc = grid.coord_of(c, 4);
    const bool inside = cc.i >= 1 && cc.i <= 6 && cc.j >= 1 && cc.j <= 6 && cc.k >= 1 && cc.k <= 6;
    EXPECT_EQ(grid.solid_cell(c, 4), inside) << c;
  }
}

TEST(GridHierarchy, TrianglesNearMatchesBruteForce) {
  const TriMesh mesh = normalized_bunny();
  const GridHierarchy grid = build_or_die(mesh, kUnitCube, 5);
  std::vector<int32_t> near;
  const Vec3 lo(-0.1, -0.05, -0.2);
  const Vec3 hi(0.05, 0.1, 0.3);
  grid.triangles_near(lo, hi, &near);
  EXPECT_TRUE(std::is_sorted(near.begin(), near.end()));
  EXPECT_EQ(std::adjacent_find(near.begin(), near.end()), near.end());
  int with_vertex_inside = 0;
  for (std::size_t t = 0; t < mesh.num_triangles(); ++t) {
    for (int32_t v : mesh.triangles[t]) {
      const Vec3& p = mesh.vertices_m[v];
      if ((p.array() >= lo.array()).all() && (p.array() <= hi.array()).all()) {
        ++with_vertex_inside;
        EXPECT_TRUE(std::binary_search(near.begin(), near.end(), static_cast<int32_t>(t))) << t;
        break;
      }
    }
  }
  EXPECT_GT(with_vertex_inside, 0);
  EXPECT_LT(near.size(), mesh.num_triangles());
  // and the other way: every triangle returned comes from a leaf the box touches, so its bounding box meets the
  // box grown by one leaf cell
  const double leaf = grid.cell_size_m(grid.levels());
  int64_t far_away = 0;
  for (int32_t t : near) {
    Vec3 tlo = mesh.vertices_m[mesh.triangles[t][0]], thi = tlo;
    for (int32_t v : mesh.triangles[t]) {
      tlo = tlo.cwiseMin(mesh.vertices_m[v]);
      thi = thi.cwiseMax(mesh.vertices_m[v]);
    }
    far_away += ((thi.array() < lo.array() - leaf).any() || (tlo.array() > hi.array() + leaf).any()) ? 1 : 0;
  }
  EXPECT_EQ(far_away, 0);
  // exactly the touched leaves' lists, merged by a comparison sort; the same with a scratch buffer reused
  std::vector<int32_t> expect;
  const CellCoord clo = grid.cell_of(lo, grid.levels()), chi = grid.cell_of(hi, grid.levels());
  for (int k = clo.k; k <= chi.k; ++k)
    for (int j = clo.j; j <= chi.j; ++j)
      for (int i = clo.i; i <= chi.i; ++i) {
        const auto ids = grid.leaf_triangles(grid.linear_index({i, j, k}, grid.levels()));
        expect.insert(expect.end(), ids.begin(), ids.end());
      }
  ASSERT_GT(expect.size(), near.size());  // leaves share triangles: there was something to merge
  std::sort(expect.begin(), expect.end());
  expect.erase(std::unique(expect.begin(), expect.end()), expect.end());
  EXPECT_EQ(near, expect);
  std::vector<int32_t> scratch, again;
  for (int round = 0; round < 2; ++round) {
    grid.triangles_near(lo, hi, &again, &scratch);
    EXPECT_EQ(again, expect) << "round " << round;
  }
  grid.triangles_near(Vec3::Constant(2), Vec3::Constant(3), &near);
  EXPECT_TRUE(near.empty());
  grid.triangles_near(hi, lo, &near);
  EXPECT_TRUE(near.empty());
}

}  // namespace
}  // namespace palpate
