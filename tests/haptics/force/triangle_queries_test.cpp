#include "haptics/force/triangle_queries.h"

#include <gtest/gtest.h>

namespace palpate {
namespace {

const Vec3 A(0, 0, 0), B(1, 0, 0), C(0, 1, 0);

TEST(TriangleQueries, ClosestPointInEachVoronoiRegion) {
  Vec3 bary;
  EXPECT_LT((closest_point_on_triangle(Vec3(0.2, 0.3, 5), A, B, C, &bary) - Vec3(0.2, 0.3, 0)).norm(), 1e-15);
  EXPECT_NEAR((bary - Vec3(0.5, 0.2, 0.3)).norm(), 0, 1e-15);
  EXPECT_EQ(closest_point_on_triangle(Vec3(-1, -1, 1), A, B, C, &bary), A);
  EXPECT_EQ(closest_point_on_triangle(Vec3(3, -1, 0), A, B, C, &bary), B);
  EXPECT_EQ(closest_point_on_triangle(Vec3(0.5, -2, 0), A, B, C, &bary), Vec3(0.5, 0, 0));
  const Vec3 q = closest_point_on_triangle(Vec3(1, 1, 0), A, B, C, &bary);
  EXPECT_NEAR((q - Vec3(0.5, 0.5, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR(bary.sum(), 1.0, 1e-15);
}

TEST(TriangleQueries, SegmentEntersOnlyFromTheFront) {
  double u = 0;
  Vec3 bary;
  EXPECT_TRUE(segment_enters_triangle(Vec3(0.2, 0.2, 1), Vec3(0.2, 0.2, -1), A, B, C, &u, &bary));
  EXPECT_NEAR(u, 0.5, 1e-15);
  EXPECT_NEAR((bary - Vec3(0.6, 0.2, 0.2)).norm(), 0, 1e-15);
  EXPECT_FALSE(segment_enters_triangle(Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), A, B, C, &u, &bary));  // from behind
  EXPECT_FALSE(segment_enters_triangle(Vec3(0.2, 0.2, 1), Vec3(0.2, 0.2, 0.5), A, B, C, &u, &bary));  // too short
  EXPECT_FALSE(segment_enters_triangle(Vec3(2, 2, 1), Vec3(2, 2, -1), A, B, C, &u, &bary));          // outside
}

}  // namespace
}  // namespace palpate
