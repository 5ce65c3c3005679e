// Ray and nearest-point queries on a loaded model, checked on a box whose answers are known.
#include "runtime/session/surface_queries.h"

#include <gtest/gtest.h>

#include "core/scene.h"

namespace palpate {
namespace {

// a 100 mm box at the origin
Model box_model() {
  Scene s;
  s.mesh.box_size_m = Vec3::Constant(0.1);
  s.mesh.size_m = 0.1;
  return load_model(s).value();
}

TEST(SurfaceQueries, RayFromAboveMeetsTheTopFaceFromItsFront) {
  const Model m = box_model();
  const auto hit = first_ray_hit(m, Vec3(0.01, -0.02, 0.3), Vec3(0, 0, -2), 1.0, true);
  ASSERT_TRUE(hit);
  EXPECT_TRUE(hit->point_m.isApprox(Vec3(0.01, -0.02, 0.05), 1e-12));
  EXPECT_TRUE(hit->normal.isApprox(Vec3::UnitZ(), 1e-12));
  EXPECT_NEAR(hit->distance_m, 0.25, 1e-12);
  // too short to reach it, or pointing away: nothing
  EXPECT_FALSE(first_ray_hit(m, Vec3(0.01, -0.02, 0.3), Vec3(0, 0, -1), 0.2, true));
  EXPECT_FALSE(first_ray_hit(m, Vec3(0.01, -0.02, 0.3), Vec3(0, 0, 1), 1.0, false));
  EXPECT_FALSE(first_ray_hit(m, Vec3(0.01, -0.02, 0.3), Vec3::Zero(), 1.0, false));
}

TEST(SurfaceQueries, RayFromInsideLeavesThroughABackFaceThatOnlyAnySideCounts) {
  const Model m = box_model();
  EXPECT_FALSE(first_ray_hit(m, Vec3::Zero(), Vec3::UnitX(), 1.0, true));
  const auto hit = first_ray_hit(m, Vec3::Zero(), Vec3::UnitX(), 1.0, false);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->point_m.x(), 0.05, 1e-12);
  EXPECT_NEAR(hit->distance_m, 0.05, 1e-12);
}

TEST(SurfaceQueries, NearestPointIsExactInsideOutsideAndFarFromTheGrid) {
  const Model m = box_model();
  auto n = nearest_surface_point(m, Vec3(0.01, 0.02, 0.09));
  ASSERT_TRUE(n);
  EXPECT_TRUE(n->point_m.isApprox(Vec3(0.01, 0.02, 0.05), 1e-12));
  EXPECT_NEAR(n->distance_m, 0.04, 1e-12);
  // inside: the nearest face, 10 mm away
  n = nearest_surface_point(m, Vec3(0.0, -0.04, 0.0));
  ASSERT_TRUE(n);
  EXPECT_NEAR(n->point_m.y(), -0.05, 1e-12);
  EXPECT_NEAR(n->distance_m, 0.01, 1e-12);
  // a metre off, beyond the grid's cube
  n = nearest_surface_point(m, Vec3(1.0, 0.0, 0.0));
  ASSERT_TRUE(n);
  EXPECT_NEAR(n->distance_m, 0.95, 1e-12);
  EXPECT_TRUE(n->normal.isApprox(Vec3::UnitX(), 1e-12));
}

// depth_inside: the box's answers are its distances to the nearest face, inside; outside, or nearer the surface than
// the reach, 0; and how far the point may move with the answer unchanged
TEST(SurfaceQueries, DepthInsideIsTheDistanceToTheSurfaceOnlyInsideAndBeyondTheReach) {
  const Model m = box_model();
  ASSERT_TRUE(m.closed);
  EXPECT_NEAR(depth_inside(m, Vec3::Zero(), 0.01), 0.05, 1e-12);          // the middle, a cell no face crosses
  EXPECT_NEAR(depth_inside(m, Vec3(0.01, 0.0, 0.046), 0.001), 0.004, 1e-12);  // 4 mm under the top, in a face's cell
  EXPECT_EQ(depth_inside(m, Vec3(0.01, 0.0, 0.046), 0.005), 0.0);          // within the reach
  EXPECT_EQ(depth_inside(m, Vec3(0.01, 0.0, 0.054), 0.001), 0.0);          // 4 mm above the top
  EXPECT_EQ(depth_inside(m, Vec3(0.3, 0.0, 0.0), 0.0), 0.0);               // beyond the grid
  double still = -1.0;
  EXPECT_EQ(depth_inside(m, Vec3(0.01, 0.0, 0.049), 0.003, &still), 0.0);
  EXPECT_NEAR(still, 0.002, 1e-12);  // 1 mm under the top with a 3 mm reach: 2 mm more before it could count
  // near an edge and a corner, outside, the nearest face turns its back to the point: the rays decide, not the face
  EXPECT_EQ(depth_inside(m, Vec3(0.052, 0.0, 0.052), 0.001), 0.0);
  EXPECT_EQ(depth_inside(m, Vec3(0.052, 0.052, 0.052), 0.001), 0.0);
  EXPECT_NEAR(depth_inside(m, Vec3(0.046, 0.0, 0.047), 0.001), 0.003, 1e-12);
}

TEST(SurfaceQueries, AnOpenSurfaceHasNoInside) {
  Model m = box_model();
  // the box without its top: every edge of the opening belongs to one triangle only
  std::vector<std::array<int32_t, 3>> kept;
  for (const auto& t : m.rest.triangles) {
    bool top = true;
    for (int c = 0; c < 3; ++c) top = top && m.rest.vertices_m[static_cast<std::size_t>(t[c])].z() > 0.05 - 1e-9;
    if (!top) kept.push_back(t);
  }
  ASSERT_LT(kept.size(), m.rest.triangles.size());
  m.rest.triangles = kept;
  m.adjacency = VertexTriangles::build(m.rest.vertices_m.size(), m.rest.triangles);
  EXPECT_FALSE(closed_surface(m.rest, m.adjacency));
  m.closed = false;
  EXPECT_EQ(depth_inside(m, Vec3::Zero(), 0.01), 0.0);
}

}  // namespace
}  // namespace palpate
