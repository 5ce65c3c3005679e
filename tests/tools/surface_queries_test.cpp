// Ray and nearest-point queries on a loaded model, checked on a box whose answers are known.
#include "tools/session/surface_queries.h"

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

}  // namespace
}  // namespace palpate
