// A person's change of the controls reaching the servo (core/controls.h): the mode's parameters and the tool's radius
// at once, no contact, and nothing felt until a patch of the session's own controls arrives; a smaller seq or one
// already seen changes nothing.
#include <gtest/gtest.h>

#include "haptics/servo/servo.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

using test::FloorRig;

// the floor z = 0 as frame `frame` of a session under controls `seq`
void publish_floor_seq(TripleBuffer<LocalModel>* tb, int64_t seq, int64_t frame) {
  LocalModel& m = tb->write_buffer();
  m.num_triangles = 0;
  test::add_quad(&m, Vec3(-0.05, -0.05, 0), Vec3(0.05, -0.05, 0), Vec3(0.05, 0.05, 0), Vec3(-0.05, 0.05, 0));
  m.frame = frame;
  m.t_s = 0.0;
  m.blend_s = 0.0;
  m.controls_seq = seq;
  tb->publish();
}

// a sphere of radius r held at height z over the floor z = 0: the coupling's force
double sphere_force(FloorRig& rig, int64_t* tick, double z_m, int ticks) {
  rig.dev.pos_m = Vec3(0, 0, z_m);
  for (int i = 0; i < ticks; ++i) rig.tick((*tick)++);
  return rig.servo->last_sample().force_N.z();
}

TEST(ServoControls, ANewSeqTakesTheModeAndRadiusAndFeelsNoPatchUntilItsOwn) {
  ServoParams p = test::static_surface_params(200.0);
  p.tool_radius_m = 0.004;  // a sphere
  FloorRig rig(p, false);
  int64_t tick = 0;
  // in from above, the sphere 1 mm into the floor: 200 N/m x 1 mm
  sphere_force(rig, &tick, 0.02, 5);
  EXPECT_NEAR(sphere_force(rig, &tick, 0.003, 20), 0.2, 1e-9);
  EXPECT_EQ(rig.servo->last_sample().contact, ContactState::kTouch);
  EXPECT_EQ(rig.servo->last_sample().controls.seq, 0);

  // seq 1: a 2 mm sphere. No contact, and the floor of seq 0 is not felt, in or out
  rig.dev.controls.seq = 1;
  rig.dev.controls.mode = InteractionMode::kTouch;
  rig.dev.controls.tool_radius_m = 0.002;
  EXPECT_EQ(sphere_force(rig, &tick, 0.003, 1), 0.0);
  EXPECT_EQ(rig.servo->last_sample().contact, ContactState::kFree);
  EXPECT_EQ(rig.servo->last_sample().controls.seq, 1);
  EXPECT_EQ(rig.servo->controls().tool_radius_m, 0.002);
  EXPECT_EQ(sphere_force(rig, &tick, 0.02, 5), 0.0);
  EXPECT_EQ(sphere_force(rig, &tick, 0.001, 5), 0.0);
  EXPECT_EQ(rig.servo->last_sample().contact, ContactState::kFree);

  // the session's patch under seq 1: in from above again, the 2 mm sphere 1 mm in
  publish_floor_seq(rig.tb.get(), 1, 1);
  sphere_force(rig, &tick, 0.02, 5);
  EXPECT_NEAR(sphere_force(rig, &tick, 0.001, 20), 0.2, 1e-9);
  EXPECT_EQ(rig.servo->last_sample().contact, ContactState::kTouch);

  // an old seq again (a device's stale state) changes nothing
  rig.dev.controls.seq = 0;
  EXPECT_NEAR(sphere_force(rig, &tick, 0.001, 3), 0.2, 1e-9);
  EXPECT_EQ(rig.servo->controls().seq, 1);
}

TEST(ServoControls, ASwitchToPullGrabsWithTheButtonAndDropsTheSphereAndFriction) {
  ServoParams p = test::static_surface_params(200.0);
  p.tool_radius_m = 0.004;
  p.friction.static_coefficient = 0.5;
  p.friction.dynamic_coefficient = 0.3;
  FloorRig rig(p, false);
  int64_t tick = 0;
  rig.dev.controls.seq = 1;
  rig.dev.controls.mode = InteractionMode::kPull;
  rig.dev.controls.tool_radius_m = 0.004;
  rig.dev.pos_m = Vec3(0, 0, 0.001);
  rig.tick(tick++);
  publish_floor_seq(rig.tb.get(), 1, 1);
  // the button on the floor grabs it; 5 mm up, the grab pulls the hand back down (a touch would give nothing)
  rig.dev.buttons = 1;
  rig.dev.pos_m = Vec3(0, 0, 0.0);
  for (int i = 0; i < 3; ++i) rig.tick(tick++);
  EXPECT_EQ(rig.servo->last_sample().contact, ContactState::kGrab);
  rig.dev.pos_m = Vec3(0, 0, 0.005);
  for (int i = 0; i < 3; ++i) rig.tick(tick++);
  EXPECT_NEAR(rig.servo->last_sample().force_N.z(), -1.0, 1e-9);
  EXPECT_EQ(rig.servo->last_sample().controls.mode, InteractionMode::kPull);
}

}  // namespace
}  // namespace palpate
