// Contact load and response: where a point tool's and a sphere tool's push goes on the lattice, the force a
// frictionless sphere passes on, and the linearised response the servo reads between frames.
#include <gtest/gtest.h>

#include <cmath>

#include "core/binding.h"
#include "sim/contact/contact_load.h"
#include "sim/contact/contact_response.h"
#include "sim/contact_block.h"
#include "sim/sim_test_util.h"

namespace palpate {
namespace {

constexpr double kSide_m = test::kContactBlockSide_m;

using Block = test::ContactBlock;

// Sum of the weights and the weighted rest position of the loaded nodes.
std::pair<double, Vec3> moments(const Lattice& lat, const PointWeights& w) {
  double sum = 0.0;
  Vec3 at = Vec3::Zero();
  for (int i = 0; i < w.count; ++i) {
    sum += w.weight[i];
    at += w.weight[i] * lat.rest_m[w.node[i]];
  }
  return {sum, at};
}

TEST(ContactLoad, PointWeightsSumToOneAndPutTheLoadAtTheMaterialPoint) {
  const Block b;
  const int32_t tri = b.top_triangle(0.005, -0.012);
  ASSERT_GE(tri, 0);
  const Vec3 bary(0.2, 0.3, 0.5);
  const PointWeights w = point_weights(b.lat, b.rest, tri, bary);
  EXPECT_EQ(w.count, 24);  // 3 corners x 8 cell nodes
  const auto [sum, at] = moments(b.lat, w);
  EXPECT_NEAR(sum, 1.0, 1e-12);
  // trilinear weights reproduce linear functions: the load's centre is the point itself
  const Vec3 p = surface_point(b.box.mesh.vertices_m, b.box.mesh.triangles[static_cast<std::size_t>(tri)], bary);
  EXPECT_NEAR((at - p).norm(), 0.0, 1e-12);
}

TEST(ContactLoad, HertzPatchIsCentredUnderTheSphereAndItsRadiusIsSqrtRDelta) {
  const Block b;
  constexpr double kRadius_m = 0.02;
  const Vec3 foot(0.004, -0.007, kSide_m / 2);
  ToolContact c;
  c.tri = b.top_triangle(foot.x(), foot.y());
  c.bary = Vec3::Constant(1.0 / 3.0);
  c.sphere = true;
  c.radius_m = kRadius_m;
  // the foot lies in the cell [0, 0.02] x [-0.02, 0]: 4 mm from the cell face x = 0 and 7 mm from y = 0. The
  // outermost ring (radius 6/6.5 a) reaches across x = 0 once a = sqrt(R delta) > 4.33 mm, across y = 0 too once
  // a > 7.58 mm: one cell (8 nodes) at 0.5 mm deep (a = 3.2 mm), two (12) at 2 mm (a = 6.3 mm), four (18) at 8 mm
  // (a = 12.6 mm)
  const std::pair<double, int> presses[] = {{0.0005, 8}, {0.002, 12}, {0.008, 18}};
  for (const auto& [depth_m, nodes] : presses) {
    c.centre_m = foot + Vec3(0, 0, kRadius_m - depth_m);
    const PointWeights w = hertz_patch_weights(b.lat, b.rest, c);
    const auto [sum, at] = moments(b.lat, w);
    EXPECT_NEAR(sum, 1.0, 1e-12) << depth_m;
    // the rings are symmetric about the foot of the centre: the load's centre is there, a hair inside the face
    EXPECT_NEAR(at.x(), foot.x(), 1e-12) << depth_m;
    EXPECT_NEAR(at.y(), foot.y(), 1e-12) << depth_m;
    EXPECT_NEAR(at.z(), foot.z() - 1e-3 * b.lat.cell_m, 1e-12) << depth_m;
    EXPECT_EQ(w.count, nodes) << depth_m;
  }
  // not pressed in: no patch, the point's own weights
  c.centre_m = foot + Vec3(0, 0, kRadius_m + 0.001);
  const PointWeights none = hertz_patch_weights(b.lat, b.rest, c);
  const PointWeights point = point_weights(b.lat, b.rest, c.tri, c.bary);
  ASSERT_EQ(none.count, point.count);
  for (int i = 0; i < point.count; ++i) EXPECT_EQ(none.weight[i], point.weight[i]);
  EXPECT_EQ(contact_load_weights(b.lat, b.rest, c).count, point.count);
}

TEST(ContactLoad, AFrictionlessSpherePassesOnlyTheNormalPush) {
  const Block b;
  ToolContact c;
  c.tri = b.top_triangle(0.0, 0.0);
  const Vec3 reaction(0.3, -0.2, -1.5);
  EXPECT_EQ(object_force(b.rest, c, reaction), reaction);  // a point tool: all of it
  c.sphere = true;
  const Vec3 f = object_force(b.rest, c, reaction);
  EXPECT_NEAR((f - Vec3(0, 0, -1.5)).norm(), 0.0, 1e-15);
}

TEST(ContactResponse, IsTheCompliancesAndTheLoadedNodesMotion) {
  Block b;
  const int32_t tri = b.top_triangle(0.0, 0.0);
  const PointWeights w = point_weights(b.lat, b.rest, tri, Vec3::Constant(1.0 / 3.0));
  for (auto& v : b.lat.v_m_per_s) v = Vec3(0.0, 0.0, -0.1);  // the whole block moving down
  ContactCompliance cc, direct;
  ContactResponse r;
  const Vec3 p(0.001, 0.002, 0.04), f(0, 0, -2.0);
  ASSERT_TRUE(contact_response(b.lat, w, p, f, &cc, &r));
  Mat3 c;
  ASSERT_TRUE(direct.compute(b.lat, w, false, &c));
  EXPECT_EQ(r.compliance_m_per_N, c);
  EXPECT_GT(r.compliance_m_per_N(2, 2), 0.0);
  EXPECT_NEAR((r.v0_m_per_s - Vec3(0, 0, -0.1)).norm(), 0.0, 1e-15);
  EXPECT_EQ(r.p0_m, p);
  EXPECT_EQ(r.f0_N, f);
  EXPECT_EQ(r.radius_m, b.lat.cell_m);
  // nothing loaded: no response, the output untouched
  ContactResponse untouched;
  untouched.radius_m = 7.0;
  EXPECT_FALSE(contact_response(b.lat, PointWeights{}, p, f, &cc, &untouched));
  EXPECT_EQ(untouched.radius_m, 7.0);
}

}  // namespace
}  // namespace palpate
