// The force limit every path to a device applies: finite forces within the limit pass unchanged, longer ones keep
// their direction at the limit's length, non-finite ones become zero.
#include "haptics/force/force_limit.h"

#include <gtest/gtest.h>

#include <limits>

namespace palpate {
namespace {

TEST(LimitForce, WithinTheLimitPassesUnchanged) {
  const Vec3 f(0.3, -1.2, 2.0);
  EXPECT_EQ(limit_force(f, 3.3), f);
  EXPECT_EQ(limit_force(Vec3::Zero(), 3.3), Vec3::Zero());
}

TEST(LimitForce, LongerForcesKeepTheirDirectionAtTheLimit) {
  const Vec3 f(3.0, 4.0, 12.0);  // 13 N
  const Vec3 g = limit_force(f, 2.6);
  EXPECT_NEAR(g.norm(), 2.6, 1e-15);
  EXPECT_NEAR((g - f * (2.6 / 13.0)).norm(), 0.0, 1e-15);
}

TEST(LimitForce, NonFiniteForcesBecomeZero) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(limit_force(Vec3(nan, 0, 0), 3.3), Vec3::Zero());
  EXPECT_EQ(limit_force(Vec3(0, inf, 0), 3.3), Vec3::Zero());
  EXPECT_EQ(limit_force(Vec3(-inf, inf, 1), 3.3), Vec3::Zero());
}

}  // namespace
}  // namespace palpate
