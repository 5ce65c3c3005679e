#include "sim/deformer.h"

#include <gtest/gtest.h>

#include "core/binding.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

struct DeformFixture {
  test::BoxModel box = test::make_box_model(0.04, 3, 6);
  Lattice lat;
  std::vector<VertexBinding> bindings;
  MeshDeformer deformer;
  std::vector<Vec3> out;

  DeformFixture() {
    lat = build_lattice(box.grid, test::spec_for(3, 40, 20, 10), region_cells(box.grid, 3, {1, 1, 1}, 64)).value();
    bindings = bind_vertices(box.grid, 3, box.mesh.vertices_m);
    deformer.attach(lat, bindings);
    out = box.mesh.vertices_m;
  }
  void run() { deformer.deform(lat, bindings, box.mesh.vertices_m, &out); }
};

TEST(Deformer, UndeformedLatticeReproducesEveryVertexExactly) {
  DeformFixture f;
  for (auto& v : f.out) v = Vec3::Constant(99.0);  // poison
  f.run();
  EXPECT_EQ(f.deformer.num_bound_vertices(), f.box.mesh.num_vertices());
  for (std::size_t i = 0; i < f.out.size(); ++i) EXPECT_EQ(f.out[i], f.box.mesh.vertices_m[i]) << "vertex " << i;
}

TEST(Deformer, UniformlyScaledLatticeScalesTheMesh) {
  DeformFixture f;
  const double s = 1.37;
  for (std::size_t i = 0; i < f.lat.num_nodes(); ++i) f.lat.x_m[i] = s * f.lat.rest_m[i];
  f.run();
  for (std::size_t i = 0; i < f.out.size(); ++i)
    EXPECT_LT((f.out[i] - s * f.box.mesh.vertices_m[i]).norm(), test::kTightTol) << "vertex " << i;
}

TEST(Deformer, RotatedCellRotatesItsVerticesWhereEq9DoesNot) {
  DeformFixture f;
  const Mat3 r = Eigen::AngleAxisd(0.6, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 pivot(0.003, -0.002, 0.001);
  for (std::size_t i = 0; i < f.lat.num_nodes(); ++i) f.lat.x_m[i] = pivot + r * (f.lat.rest_m[i] - pivot);
  f.run();
  double eq9_worst = 0.0;
  for (std::size_t i = 0; i < f.out.size(); ++i) {
    const Vec3 want = pivot + r * (f.box.mesh.vertices_m[i] - pivot);
    EXPECT_LT((f.out[i] - want).norm(), test::kTightTol) << "vertex " << i;
    const int32_t slot = f.lat.slot_of_cell[f.bindings[i].cell];
    eq9_worst = std::max(eq9_worst, (deform_eq9(f.lat, slot, f.bindings[i].local) - want).norm());
  }
  EXPECT_GT(eq9_worst, 0.1 * f.lat.cell_m);  // eq. (9) keeps cells axis-aligned: it cannot rotate
}

TEST(Deformer, Eq9AndTrilinearAgreeForBoxShapedCells) {
  DeformFixture f;
  // stretch each axis differently: every cell stays a box
  const Vec3 s(1.2, 0.9, 1.1);
  for (std::size_t i = 0; i < f.lat.num_nodes(); ++i) f.lat.x_m[i] = f.lat.rest_m[i].cwiseProduct(s);
  f.run();
  for (std::size_t i = 0; i < f.out.size(); ++i) {
    const int32_t slot = f.lat.slot_of_cell[f.bindings[i].cell];
    EXPECT_LT((deform_eq9(f.lat, slot, f.bindings[i].local) - f.out[i]).norm(), 1e-12);
  }
}

TEST(Deformer, VerticesOutsideTheRegionStayPut) {
  test::BoxModel box = test::make_box_model(0.04, 3, 6);
  const Lattice lat = build_lattice(box.grid, test::spec_for(3, 40, 20, 10), region_cells(box.grid, 3, {0, 0, 0}, 0)).value();
  const auto bindings = bind_vertices(box.grid, 3, box.mesh.vertices_m);
  MeshDeformer d;
  d.attach(lat, bindings);
  EXPECT_LT(d.num_bound_vertices(), box.mesh.num_vertices());
  for (int32_t v : d.vertex_ids()) EXPECT_GE(lat.slot_of_cell[bindings[v].cell], 0);
  // deform it: every free node moved; the region's vertices move, every other vertex keeps its rest position
  Lattice moved = lat;
  for (std::size_t i = 0; i < moved.num_nodes(); ++i)
    if (!moved.fixed[i]) moved.x_m[i] += Vec3(0.002, -0.001, 0.003);
  std::vector<Vec3> out = box.mesh.vertices_m;
  d.deform(moved, bindings, box.mesh.vertices_m, &out);
  std::vector<uint8_t> bound(out.size(), 0);
  for (int32_t v : d.vertex_ids()) bound[v] = 1;
  int64_t region_moved = 0, outside_moved = 0;
  for (std::size_t v = 0; v < out.size(); ++v) {
    const bool changed = out[v] != box.mesh.vertices_m[v];
    (bound[v] ? region_moved : outside_moved) += changed ? 1 : 0;
  }
  EXPECT_GT(region_moved, 0);
  EXPECT_EQ(outside_moved, 0);
}

}  // namespace
}  // namespace palpate
