#include "sim/lattice/deformer.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "core/binding.h"
#include "sim/material/strain.h"
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

// The strain a frame is coloured by, against closed forms: none for a rigid motion or a pure dilation (no change of
// shape), 2/3 |e + e^2/2| for a uniaxial stretch e, and the same at every node and surface vertex of a lattice under
// a uniform deformation (interpolated as positions are).
TEST(Strain, EquivalentStrainMatchesClosedFormsAndIsInterpolatedToTheSurface) {
  DeformFixture f;
  auto apply = [&](const Mat3& F, const Vec3& shift) {
    for (std::size_t i = 0; i < f.lat.num_nodes(); ++i) f.lat.x_m[i] = F * f.lat.rest_m[i] + shift;
  };
  auto node_range = [&] {
    std::vector<double> e;
    std::vector<int> n;
    node_equivalent_strain(f.lat, &e, &n);
    EXPECT_EQ(e.size(), f.lat.num_nodes());
    return std::make_pair(*std::min_element(e.begin(), e.end()), *std::max_element(e.begin(), e.end()));
  };
  const Mat3 rot = Eigen::AngleAxisd(0.9, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  apply(rot, Vec3(0.01, 0.02, -0.03));
  EXPECT_LT(node_range().second, 1e-12);
  apply(1.3 * Mat3::Identity(), Vec3::Zero());
  EXPECT_LT(node_range().second, 1e-12);
  for (double e : {0.2, -0.1}) {
    Mat3 F = Mat3::Identity();
    F(2, 2) = 1.0 + e;
    apply(rot * F, Vec3::Zero());  // stretched along z, then turned: the same strain
    const auto [lo, hi] = node_range();
    const double want = 2.0 / 3.0 * std::abs(e + 0.5 * e * e);
    EXPECT_NEAR(lo, want, 1e-12) << "e " << e;
    EXPECT_NEAR(hi, want, 1e-12) << "e " << e;
    std::vector<double> nodes;
    std::vector<int> count;
    node_equivalent_strain(f.lat, &nodes, &count);
    std::vector<float> at_vertex(f.box.mesh.num_vertices(), -1.0f);
    f.deformer.interpolate(f.lat, f.bindings, f.box.mesh.vertices_m, nodes, &at_vertex);
    for (float v : at_vertex) EXPECT_NEAR(v, want, 1e-6) << "e " << e;
  }
  // a dent: the strain is largest at the node pushed in, and nothing beyond its cells strains
  apply(Mat3::Identity(), Vec3::Zero());
  std::size_t pushed = 0;
  for (std::size_t i = 0; i < f.lat.num_nodes(); ++i)
    if ((f.lat.rest_m[i] - Vec3(0.02, 0.02, 0.02)).norm() < (f.lat.rest_m[pushed] - Vec3(0.02, 0.02, 0.02)).norm())
      pushed = i;
  f.lat.x_m[pushed].z() -= 0.2 * f.lat.cell_m;
  std::vector<double> nodes;
  std::vector<int> count;
  node_equivalent_strain(f.lat, &nodes, &count);
  EXPECT_EQ(std::max_element(nodes.begin(), nodes.end()) - nodes.begin(), static_cast<std::ptrdiff_t>(pushed));
  for (std::size_t i = 0; i < f.lat.num_nodes(); ++i) {
    if ((f.lat.rest_m[i] - f.lat.rest_m[pushed]).cwiseAbs().maxCoeff() > 2.5 * f.lat.cell_m) {
      EXPECT_LT(nodes[i], 1e-12);
    }
  }
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
