// Between sim frames the servo moves the surface from the last frame's corners to the new frame's over the frame,
// so a surface that moved (the lattice stepped, a region placed or moved) reaches the hand in steps of a tick's
// share, not in one step at the frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "haptics/servo/servo.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

constexpr double kK = 300.0;

struct Steps {
  double largest_N = 0.0;   // largest force step per tick after the surface moved
  double settled_N = 0.0;   // the force 20 ticks after the frame
};

// a still device 2 mm under the floor z = 0; at tick 100 a frame moves the floor down 1 mm
Steps run(double radius, bool blend) {
  ServoParams p = test::static_surface_params(kK);
  p.tool_radius_m = radius;
  test::FloorRig rig(p, blend);
  Steps s;
  Vec3 prev = Vec3::Zero();
  for (int i = 0; i < 130; ++i) {
    rig.dev.pos_m = Vec3(0.001, 0.002, radius + 0.002 - std::min(1.0, i / 50.0) * 0.004);
    if (i == 100) test::publish_floor_at(rig.tb.get(), -0.001, 0.0, 1, i * 1e-3, blend);
    rig.tick(i);
    const ContactState contact = rig.servo->last_sample().contact;
    EXPECT_EQ(contact, i < 50 ? contact : ContactState::kTouch) << i;
    if (i >= 100) s.largest_N = std::max(s.largest_N, (rig.dev.force_N - prev).norm());
    if (i == 120) s.settled_N = rig.dev.force_N.z();
    prev = rig.dev.force_N;
  }
  return s;
}

TEST(SurfaceBlend, AFrameThatMovesTheSurfaceReachesAStillDeviceInTicksShares) {
  for (double radius : {0.0, 0.005}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    // the floor drops 1 mm under a device held 2 mm deep: 0.6 N becomes 0.3 N
    const Steps blended = run(radius, true), stepped = run(radius, false);
    EXPECT_NEAR(blended.settled_N, kK * 0.001, 1e-9);
    EXPECT_NEAR(stepped.settled_N, kK * 0.001, 1e-9);
    EXPECT_NEAR(stepped.largest_N, kK * 0.001, 1e-9);  // without the blend: all of it in one tick
    // blended: over the frame's ticks (16 at 1 kHz / 60 Hz), each a share 1 / (frame - tick) of 0.3 N
    const double share = kK * 0.001 * test::kTestRates.servo_period_s() /
                         (test::kTestRates.frame_period_s() - test::kTestRates.servo_period_s());
    EXPECT_LE(blended.largest_N, share + 1e-9);
  }
}

// A realtime frame that comes before the last one's way is done (the sim late by a frame, then on time): the floor
// drops 1 mm at tick 100 and, 5 ticks into that frame's way, a frame drops it 1 mm more. The surface goes on from
// where the hand felt it, never jumping to where the last frame would have put it.
TEST(SurfaceBlend, AFrameThatComesEarlyGoesOnFromWhereTheSurfaceIs) {
  ServoParams p = test::static_surface_params(kK);
  test::FloorRig rig(p, true);
  double largest_N = 0.0;
  Vec3 prev = Vec3::Zero();
  for (int i = 0; i < 140; ++i) {
    rig.dev.pos_m = Vec3(0.001, 0.002, -std::min(1.0, i / 50.0) * 0.003);  // a still device 3 mm under z = 0
    if (i == 100) test::publish_floor_at(rig.tb.get(), -0.001, 0.0, 1, i * 1e-3, true);
    if (i == 105) test::publish_floor_at(rig.tb.get(), -0.002, -0.001, 2, i * 1e-3, true);
    rig.tick(i);
    if (i >= 100) largest_N = std::max(largest_N, (rig.dev.force_N - prev).norm());
    if (i == 135) {
      EXPECT_NEAR(rig.dev.force_N.z(), kK * 0.001, 1e-9);  // the second frame's floor, 1 mm over the device
    }
    prev = rig.dev.force_N;
  }
  // the way left (1.7 mm) over the new frame's ticks, each a share of it; from the last frame's corners instead, the
  // first tick took the 0.7 mm the first frame had not yet gone at once (0.2 N)
  const double share = kK * 0.002 * test::kTestRates.servo_period_s() /
                       (test::kTestRates.frame_period_s() - test::kTestRates.servo_period_s());
  EXPECT_LE(largest_N, share + 1e-9) << "the surface jumped when the early frame came";
}

}  // namespace
}  // namespace palpate
