// A surface that moves through a tool is met by it as if the tool had moved: a soft surface driven past a point
// tool's tip (the contact released) that springs back up through the still tool touches it again, instead of
// leaving it inside the object, untouched, for good (the soft cube_press at level 6 held 0 N after its first 28 ms).
#include <gtest/gtest.h>

#include <algorithm>

#include "haptics/servo.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

constexpr double kK = 300.0;

struct Rebound {
  bool released = false;   // contact lost while the floor was below the tool
  HapticSample last;       // the last tick's sample
};

// a device lowered from 2 mm above the floor z = 0 to depth_m into it by tick 50, then held still; the floor drops
// 2 mm past the tool's bottom with the frame at tick 100 and comes back to z = 0 with the frame at tick 133
Rebound rebound(double radius_m, double depth_m, bool blend) {
  ServoParams p = test::static_surface_params(kK);
  p.tool_radius_m = radius_m;
  test::FloorRig rig(p, blend);
  const double low_m = -depth_m - 0.002;
  Rebound r;
  for (int i = 0; i < 200; ++i) {
    rig.dev.pos_m = Vec3(0.001, 0.002, radius_m + 0.002 - std::min(1.0, i / 50.0) * (0.002 + depth_m));
    if (i == 100) test::publish_floor_at(rig.tb.get(), low_m, 0.0, 1, i * 1e-3, blend);
    if (i == 133) test::publish_floor_at(rig.tb.get(), 0.0, low_m, 2, i * 1e-3, blend);
    rig.tick(i);
    if (i > 100 && i < 133 && rig.servo->last_sample().contact == ContactState::kFree) r.released = true;
  }
  r.last = rig.servo->last_sample();
  return r;
}

TEST(MovingSurface, ASurfaceSpringingBackThroughAStillToolTouchesItAgain) {
  struct Case {
    const char* name;
    double radius_m, depth_m;
    bool blend;
  };
  // a point tool (the surface passes it over the frame's blend), and a sphere whose surface comes back in one tick
  // from past its bottom to past its centre (no blend), where its radius test alone cannot see it
  for (const Case& c : {Case{"point, blended", 0.0, 0.002, true}, Case{"point, in one tick", 0.0, 0.002, false},
                        Case{"sphere, in one tick", 0.002, 0.003, false}}) {
    SCOPED_TRACE(c.name);
    const Rebound r = rebound(c.radius_m, c.depth_m, c.blend);
    EXPECT_TRUE(r.released);  // the floor was below the tool: no contact then
    // back in touch, the proxy on the surface (a sphere's centre its radius out), the force k times the depth
    EXPECT_EQ(r.last.contact, ContactState::kTouch);
    EXPECT_NEAR(r.last.proxy_pos_m.z(), c.radius_m, 1e-9);
    EXPECT_NEAR(r.last.force_N.z(), kK * c.depth_m, 1e-9);
    EXPECT_NEAR(r.last.force_N.template head<2>().norm(), 0.0, 1e-9);
  }
}

TEST(MovingSurface, AToolThatWasNeverOutsideStaysFreeAsTheSurfaceMoves) {
  // a device held 1 mm inside from the start while the floor rises 2 mm round it: nothing was ever touched
  test::FloorRig rig(test::static_surface_params(kK), true);
  rig.dev.pos_m = Vec3(0.001, 0.002, -0.001);
  for (int i = 0; i < 80; ++i) {
    if (i == 20) test::publish_floor_at(rig.tb.get(), 0.002, 0.0, 1, i * 1e-3, true);
    rig.tick(i);
    ASSERT_EQ(rig.servo->last_sample().contact, ContactState::kFree) << i;
  }
}

}  // namespace
}  // namespace palpate
