// A cut frame's mesh work follows the blade, not the mesh: on a 50k-triangle block the vertices a frame moves and
// the normals it recomputes stay within the cells the blade's quads reached (or the cells whose nodes moved), and
// the result is what moving every vertex and recomputing every normal gives, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/binding.h"
#include "core/tri_mesh.h"
#include "sim/cut/cut_model.h"
#include "sim/sim_test_util.h"

namespace palpate {
namespace {

constexpr double kSide_m = 0.08;  // block from -0.04 to 0.04, level 3 cells of 2 cm
constexpr int kLevel = 3;
constexpr int kSubdivisions = 64;  // 6 x 64 x 64 x 2 = 49,152 triangles

struct BigBlock {
  test::BoxModel box = test::make_box_model(kSide_m, 4, kSubdivisions);
  LatticeSpec spec = test::spec_for(kLevel, 40, 20, 10);
  Lattice lat = build_lattice(box.grid, spec, region_cells(box.grid, kLevel, {1, 1, 1}, 8)).value();
  CutModel cut{box.mesh, bind_vertices(box.grid, kLevel, box.mesh.vertices_m), &box.grid, kLevel, 0.2};
  std::vector<Vec3> vertices = box.mesh.vertices_m;
  std::vector<Vec3> normals;

  // vertices now bound to the cells listed (each once)
  std::size_t vertices_in(std::vector<int32_t> cells) const {
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    std::vector<int32_t> v;
    for (int32_t c : cells) cut.vertices_in_cell(c, &v);
    return v.size();
  }
};

// The cells a box grown by one cell overlaps.
void cells_near(const CutModel& cut, const Vec3& lo_m, const Vec3& hi_m, double cell_m, std::vector<int32_t>* cells) {
  cut.cells_in_box(lo_m - Vec3::Constant(cell_m), hi_m + Vec3::Constant(cell_m), cells);
}

// Every vertex moved and every normal recomputed from scratch equal what the frame's work left, bit for bit.
void expect_same_as_whole_mesh(const BigBlock& b) {
  std::vector<Vec3> all_vertices;
  b.cut.deform(b.lat, &all_vertices);
  ASSERT_EQ(all_vertices.size(), b.vertices.size());
  EXPECT_TRUE(all_vertices == b.vertices);
  std::vector<Vec3> all_normals;
  compute_vertex_normals(b.vertices, b.cut.triangles(), &all_normals);
  ASSERT_EQ(all_normals.size(), b.normals.size());
  EXPECT_TRUE(all_normals == b.normals);
}

TEST(CutWork, AFramesVerticesAndNormalsStayWithinTheCellsTheBladeReached) {
  BigBlock b;
  const std::size_t n_v = b.vertices.size();
  ASSERT_GT(b.box.mesh.triangles.size(), 49000u);
  // the first frame takes every vertex and normal
  EXPECT_EQ(b.cut.deform_changed(b.lat, &b.vertices), n_v);
  EXPECT_EQ(b.cut.update_normals(b.vertices, &b.normals), n_v);
  // then nothing changed: nothing to do
  EXPECT_EQ(b.cut.deform_changed(b.lat, &b.vertices), 0u);
  EXPECT_EQ(b.cut.update_normals(b.vertices, &b.normals), 0u);

  // a stroke along y through the block's top 2 cm, a few servo samples a frame
  const Vec3 axis = Vec3::UnitZ();
  std::size_t most_normals = 0, frames_cut = 0;
  for (int frame = 0; frame < 12; ++frame) {
    for (int i = 0; i < 10; ++i) b.cut.add_sample({0.004, -0.06 + 0.001 * (10 * frame + i), 0.02}, axis, true);
    const CutReport rep = b.cut.apply(&b.lat, &b.vertices);
    const std::size_t deformed = b.cut.deform_changed(b.lat, &b.vertices);
    const std::size_t normals = b.cut.update_normals(b.vertices, &b.normals);
    // the bound: the vertices bound to the cells within a cell of the quads this frame cut with
    std::vector<int32_t> cells;
    for (const BladeQuad& q : b.cut.last_quads()) {
      CutBox box;
      box.add(q);
      cells_near(b.cut, box.lo_m, box.hi_m, b.lat.cell_m, &cells);
    }
    const std::size_t reach = b.vertices_in(cells);
    EXPECT_LE(deformed, reach) << "frame " << frame;
    EXPECT_LE(normals, reach) << "frame " << frame;
    EXPECT_LT(reach, n_v / 2) << "frame " << frame;  // the bound is far from the mesh (2 cm cells)
    if (rep.split.edges_cut > 0) {
      ++frames_cut;
      EXPECT_GE(normals, static_cast<std::size_t>(rep.split.vertices_added));
    }
    most_normals = std::max(most_normals, normals);
    expect_same_as_whole_mesh(b);
  }
  EXPECT_GT(frames_cut, 3u);
  EXPECT_GT(most_normals, 0u);
  // the blade reaches two cells deep and crosses about 24 mesh edges a frame: a few hundred normals at most
  EXPECT_LT(most_normals, n_v / 20);

  // a piece moves (the nodes of the cells below x = -0.02 shift): only the vertices of the cells with a moved node
  // are moved, and only normals within a cell of them recomputed
  std::vector<int32_t> moved_cells;
  for (std::size_t i = 0; i < b.lat.num_nodes(); ++i)
    if (b.lat.rest_m[i].x() < -0.021) b.lat.x_m[i] += Vec3(-0.001, 0.0005, -0.002);
  for (std::size_t s = 0; s < b.lat.cells.size(); ++s)
    for (int32_t node : b.lat.cell_nodes[s])
      if (b.lat.x_m[node] != b.lat.rest_m[node]) {
        moved_cells.push_back(b.lat.cells[s]);
        break;
      }
  ASSERT_FALSE(moved_cells.empty());
  const std::size_t deformed = b.cut.deform_changed(b.lat, &b.vertices);
  const std::size_t normals = b.cut.update_normals(b.vertices, &b.normals);
  std::vector<int32_t> near;
  for (int32_t c : moved_cells) {
    const CellCoord cc = b.box.grid.coord_of(c, kLevel);
    const Vec3 lo = b.box.grid.cube().min_m + b.lat.cell_m * Vec3(cc.i, cc.j, cc.k);
    cells_near(b.cut, lo + Vec3::Constant(0.25 * b.lat.cell_m), lo + Vec3::Constant(0.75 * b.lat.cell_m), b.lat.cell_m,
               &near);
  }
  EXPECT_EQ(deformed, b.vertices_in(moved_cells));
  EXPECT_LE(normals, b.vertices_in(near));
  EXPECT_LT(normals, n_v / 2);
  EXPECT_GT(normals, 0u);
  expect_same_as_whole_mesh(b);
}

// What testing every triangle's current box against [lo_m, hi_m] gives, ascending.
std::vector<int32_t> every_triangle_in_box(const BigBlock& b, const Vec3& lo_m, const Vec3& hi_m) {
  std::vector<int32_t> out;
  const auto& tris = b.cut.triangles();
  for (std::size_t t = 0; t < tris.size(); ++t)
    if (triangle_box_overlaps(b.vertices[tris[t][0]], b.vertices[tris[t][1]], b.vertices[tris[t][2]], lo_m, hi_m))
      out.push_back(static_cast<int32_t>(t));
  return out;
}

// The servo's patch search (CutModel::triangles_in_box) tests only triangles near its box, through the cuts that split
// and add triangles and a piece that moves, and finds what testing every triangle finds, in the same order.
TEST(CutWork, ThePatchSearchTestsTheTrianglesNearItsBoxAndFindsWhatTestingEveryTriangleFinds) {
  BigBlock b;
  const std::size_t n_t = b.cut.triangles().size();
  b.cut.deform_changed(b.lat, &b.vertices);
  b.cut.update_normals(b.vertices, &b.normals);
  std::vector<int32_t> found;
  auto search = [&](const Vec3& lo_m, const Vec3& hi_m, const char* what, int frame) {
    b.cut.triangles_in_box(b.vertices, lo_m, hi_m, &found);
    EXPECT_EQ(found, every_triangle_in_box(b, lo_m, hi_m)) << what << " frame " << frame;
    // those tested lie within 4 mm (a grid cell here is under 2 mm) of the box or of the box brought inside the
    // block (a box beyond the grid's edge is taken to its border cells)
    const Vec3 edge = Vec3::Constant(kSide_m / 2), grow = Vec3::Constant(0.004);
    auto near = every_triangle_in_box(b, lo_m.cwiseMax(-edge).cwiseMin(edge) - grow, hi_m.cwiseMax(-edge).cwiseMin(edge) + grow);
    const auto around = every_triangle_in_box(b, lo_m - grow, hi_m + grow);
    near.insert(near.end(), around.begin(), around.end());
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    EXPECT_LE(b.cut.last_box_tested(), near.size()) << what << " frame " << frame;
    EXPECT_LT(b.cut.last_box_tested(), n_t / 10) << what << " frame " << frame;
  };
  const Vec3 axis = Vec3::UnitZ();
  bool split = false;
  for (int frame = 0; frame < 12; ++frame) {
    Vec3 tip;
    for (int i = 0; i < 10; ++i) {
      tip = {0.004, -0.06 + 0.001 * (10 * frame + i), 0.02};
      b.cut.add_sample(tip, axis, true);
    }
    const CutReport rep = b.cut.apply(&b.lat, &b.vertices);
    split = split || rep.split.triangles_added > 0;
    b.cut.deform_changed(b.lat, &b.vertices);
    b.cut.update_normals(b.vertices, &b.normals);
    // the blade from its tip 2 mm into the block to its end above it, 3 mm around
    search(tip - Vec3(0.003, 0.003, 0.005), tip + Vec3(0.003, 0.003, 0.203), "stroke", frame);
  }
  EXPECT_TRUE(split);
  EXPECT_GT(b.cut.triangles().size(), n_t);
  // a piece moves 5 mm down and out: its triangles are found where they are now, not where they were
  for (std::size_t i = 0; i < b.lat.num_nodes(); ++i)
    if (b.lat.rest_m[i].x() < -0.021) b.lat.x_m[i] += Vec3(-0.005, 0.0, -0.005);
  b.cut.deform_changed(b.lat, &b.vertices);
  search(Vec3(-0.05, -0.01, -0.05), Vec3(-0.043, 0.01, -0.04), "moved piece", 12);
  EXPECT_GT(found.size(), 10u);
  search(Vec3(-0.041, -0.01, -0.045), Vec3(-0.039, 0.01, -0.035), "where it was", 12);
}

}  // namespace
}  // namespace palpate
