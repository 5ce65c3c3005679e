#include "haptics/servo/servo.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "haptics/servo/latency_histogram.h"
#include "haptics/devices/scripted_device.h"
#include "haptics/servo/servo_runner.h"
#include "support/alloc_counter.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

using test::FixedDevice;
using test::publish_floor;

// Coupling 300 N/m without damping, ramp or jump limit.
ServoParams floor_params(InteractionMode mode) {
  ServoParams p;
  p.mode = mode;
  p.coupling_N_per_m = 300;
  p.coupling_damping_Ns_per_m = 0.0;
  p.ramp_s = 0.0;
  p.jump_limit_N_per_tick = 0.0;  // the coupling's own force, tick by tick (the limit: jump_limit_test.cpp)
  return p;
}

// A servo of floor_params over the floor of publish_floor; tick() runs the next tick.
struct FloorServo : test::ServoRig<> {
  explicit FloorServo(InteractionMode mode) : ServoRig(floor_params(mode), 100000) { publish_floor(tb.get()); }
  int64_t t = 0;
  void tick() { ServoRig::tick(t++); }
};

TEST(Servo, TouchForceIsCouplingSpringToTheSurface) {
  FloorServo r(InteractionMode::kTouch);
  r.dev.pos_m = Vec3(0.01, 0.0, 0.01);
  r.tick();
  EXPECT_EQ(r.servo->last_sample().contact, ContactState::kFree);
  EXPECT_EQ(r.dev.force_N, Vec3::Zero());
  r.dev.pos_m = Vec3(0.01, 0.0, -0.002);  // crossed the surface
  r.tick();
  EXPECT_EQ(r.servo->last_sample().contact, ContactState::kTouch);
  EXPECT_NEAR(r.dev.force_N.z(), 300 * 0.002, 1e-9);
  EXPECT_NEAR(r.servo->last_sample().proxy_pos_m.z(), 0.0, 1e-12);
  // sliding: P_s follows along the surface
  r.dev.pos_m = Vec3(0.02, 0.01, -0.003);
  r.tick();
  EXPECT_NEAR((r.servo->last_sample().proxy_pos_m - Vec3(0.02, 0.01, 0)).norm(), 0.0, 1e-12);
  // leaving
  r.dev.pos_m = Vec3(0.02, 0.01, 0.003);
  r.tick();
  EXPECT_EQ(r.servo->last_sample().contact, ContactState::kFree);
  EXPECT_EQ(r.dev.force_N, Vec3::Zero());
}

TEST(Servo, ForceIsClampedToTheDeviceMaximum) {
  FloorServo r(InteractionMode::kTouch);
  r.dev.pos_m = Vec3(0, 0, 0.01);
  r.tick();
  r.dev.pos_m = Vec3(0, 0, -0.04);  // 300 N/m * 4 cm = 12 N > 3.3 N
  r.tick();
  EXPECT_NEAR(r.dev.force_N.norm(), r.dev.specs_.max_force_N, 1e-9);
  EXPECT_GT(r.dev.force_N.z(), 0.0);
}

TEST(Servo, PullForceIsClampedToALowerDeviceMaximumToo) {
  FloorServo r(InteractionMode::kPull);
  r.dev.specs_.max_force_N = 1.0;
  r.dev.pos_m = Vec3(0.01, 0.02, 0.001);
  r.tick();
  r.dev.buttons = 1;
  r.tick();
  ASSERT_EQ(r.servo->last_sample().contact, ContactState::kGrab);
  r.dev.pos_m = Vec3(0.01, 0.02, 0.03);  // 300 N/m * 3 cm = 9 N, along -z
  r.tick();
  EXPECT_NEAR(r.dev.force_N.norm(), 1.0, 1e-12);
  EXPECT_NEAR(r.dev.force_N.z(), -1.0, 1e-12);
  EXPECT_EQ(r.servo->last_sample().force_N, r.dev.force_N);  // the log shows what the device was sent
}

TEST(Servo, ForceRampsBackInAfterTheDeviceWentSilent) {
  // pressed 2 mm into the floor (0.6 N); the link goes silent for 10 ticks, then comes back: zero force while
  // silent, then a linear ramp over ramp_s from the first good reading, not a step back to 0.6 N
  FloorServo r(InteractionMode::kTouch);
  ServoParams p = floor_params(InteractionMode::kTouch);
  p.ramp_s = 0.05;
  r.servo = r.make_servo(p);
  r.dev.pos_m = Vec3(0.01, 0.0, 0.01);
  r.tick();
  r.dev.pos_m = Vec3(0.01, 0.0, -0.002);
  for (int i = 0; i < 100; ++i) r.tick();
  ASSERT_NEAR(r.dev.force_N.z(), 0.6, 1e-9);  // the start ramp is over
  r.dev.online = false;
  for (int i = 0; i < 10; ++i) {
    r.tick();
    EXPECT_EQ(r.dev.force_N, Vec3::Zero()) << "silent tick " << i;
  }
  EXPECT_EQ(r.servo->counters().no_readings, 10);
  r.dev.online = true;
  const int64_t back = r.t;
  for (int i = 0; i <= 60; ++i) {
    r.tick();
    const double expect = 0.6 * std::min(1.0, static_cast<double>(r.t - 1 - back) * 1e-3 / p.ramp_s);
    EXPECT_NEAR(r.dev.force_N.z(), expect, 1e-9) << "tick " << i << " after the link came back";
  }
  EXPECT_EQ(r.servo->counters().ramps, 2);  // the start and the return
}

TEST(Servo, PullGrabsOnPressAndHoldsTheMaterialPoint) {
  FloorServo r(InteractionMode::kPull);
  ServoParams p;
  p.mode = InteractionMode::kPull;
  p.coupling_N_per_m = 300;
  p.coupling_damping_Ns_per_m = 0;
  p.grab_radius_m = 0.01;
  p.ramp_s = 0.0;
  p.jump_limit_N_per_tick = 0.0;
  r.servo = r.make_servo(p);
  r.dev.pos_m = Vec3(0.01, 0.02, 0.005);
  r.tick();
  r.dev.buttons = 1;
  r.tick();
  ASSERT_EQ(r.servo->last_sample().contact, ContactState::kGrab);
  EXPECT_EQ(r.servo->last_sample().contact_tri, 11);
  r.dev.pos_m = Vec3(0.01, 0.02, 0.008);  // pull up: force points back down to the grabbed point
  r.tick();
  EXPECT_NEAR(r.dev.force_N.z(), -300 * 0.008, 1e-9);
  EXPECT_NEAR(r.servo->last_sample().proxy_pos_m.z(), 0.0, 1e-12);
  r.dev.buttons = 0;
  r.tick();
  EXPECT_EQ(r.servo->last_sample().contact, ContactState::kFree);
  // pressing again far from the surface does not grab
  r.dev.pos_m = Vec3(0.01, 0.02, 0.05);
  r.dev.buttons = 1;
  r.tick();
  EXPECT_EQ(r.servo->last_sample().contact, ContactState::kFree);
}

TEST(Servo, NonFiniteOrOutOfWorkspaceInputIsRejectedWithZeroForce) {
  FloorServo r(InteractionMode::kTouch);
  r.dev.pos_m = Vec3(0, 0, 0.01);
  r.tick();
  r.dev.pos_m = Vec3(0, 0, -0.002);
  r.tick();
  ASSERT_GT(r.dev.force_N.norm(), 0.0);
  r.dev.pos_m = Vec3(NAN, 0, 0);
  r.tick();
  EXPECT_EQ(r.dev.force_N, Vec3::Zero());
  EXPECT_EQ(r.servo->last_sample().tool_pos_m, Vec3(0, 0, -0.002));  // last good pose kept
  r.dev.pos_m = Vec3(0, 0, 5.0);
  r.tick();
  EXPECT_EQ(r.servo->counters().rejected_inputs, 2);
  EXPECT_TRUE(r.servo->last_sample().force_N.allFinite());
}

TEST(Servo, FullQueueDropsAndCounts) {
  test::ServoRig<> rig(ServoParams{}, 5);
  for (int i = 0; i < 12; ++i) rig.servo->tick(i, i * 1e-3);  // nothing drains the queue
  EXPECT_EQ(rig.servo->counters().dropped_samples, 7);
  EXPECT_EQ(rig.servo->counters().ticks, 12);
}

TEST(Servo, TenThousandTicksAllocateNothing) {
  Scene scene;
  scene.trajectory = {{0.0, Vec3(0, 0, 0.01), false}, {5.0, Vec3(0.01, 0, -0.01), true}, {10.0, Vec3(0, 0, 0.01), false}};
  // one servo a run, over the rig's device, queue and buffer
  test::ServoRig<ScriptedDevice> rig(ServoParams{}, 1024, test::kTestRates, DeviceSpecs{}, HandSpec{},
                                     scene.trajectory);
  TripleBuffer<LocalModel>* tb = rig.tb.get();
  publish_floor(tb);
  {
    // with the multirate contact model published, so its per-tick solve is counted too
    LocalModel& m = tb->write_buffer();
    m = tb->read();
    m.has_contact_model = true;
    m.compliance_m_per_N = Mat3::Identity() * 0.01;
    m.model_radius_m = 1.0;
    m.blend_s = 1.0 / 60.0;
    m.tri_from_m = m.tri_m;
    // shading normals tilted from the floor's, so force shading turns the force (and its blend runs)
    for (int t = 0; t < m.num_triangles; ++t)
      for (int c = 0; c < 3; ++c) m.shade_normal[t][c] = Vec3(0.1, 0.0, 1.0).normalized();
    m.shade_normal_from = m.shade_normal;
    tb->publish();
  }
  // the frames published while it runs (copied from here: a copy allocates nothing)
  auto frame = std::make_unique<LocalModel>(tb->read());
  // touch with a point tool, with a 5 mm sphere, pull, cut; then touch with friction and every mode with the
  // jump limit; touch with each frame's surface taken at once (no blend); last touch with force shading, a point and a
  // sphere, with and without friction
  struct RunSpec {
    InteractionMode mode;
    double radius, friction, jump_limit;
    bool blend = true;
    double shading_deg = 0.0;
  };
  const RunSpec runs[] = {{InteractionMode::kTouch, 0.0, 0.0, 0.0},  {InteractionMode::kTouch, 0.005, 0.0, 0.0},
                          {InteractionMode::kPull, 0.0, 0.0, 0.0},   {InteractionMode::kCut, 0.0, 0.0, 0.0},
                          {InteractionMode::kTouch, 0.0, 0.5, 0.02}, {InteractionMode::kTouch, 0.005, 0.5, 0.02},
                          {InteractionMode::kPull, 0.0, 0.0, 0.02},  {InteractionMode::kCut, 0.0, 0.0, 0.02},
                          {InteractionMode::kTouch, 0.0, 0.5, 0.02, false},
                          {InteractionMode::kTouch, 0.0, 0.0, 0.02, true, 60.0},
                          {InteractionMode::kTouch, 0.005, 0.5, 0.02, true, 60.0}};
  for (const RunSpec& run : runs) {
    const auto [mode, radius, mu, jump, blend, shading] = run;
    ServoParams p;
    p.force_shading_deg = shading;
    p.surface_blend = blend;
    p.mode = mode;
    p.tool_radius_m = radius;
    p.friction.static_coefficient = mu;
    p.friction.dynamic_coefficient = 0.7 * mu;
    p.friction.trail_drop_m = 1e-4;
    p.jump_limit_N_per_tick = jump;
    const std::unique_ptr<Servo> servo = rig.make_servo(p);  // at 1 kHz
    int64_t allocs = 0;
    {
      test::AllocationGuard guard;
      for (int i = 0; i < 10000; ++i) {
        if (i % 17 == 5) {
          // a new frame whose surface the servo blends from the last one's corners over the frame
          LocalModel& w = tb->write_buffer();
          w = *frame;
          w.frame = i;
          w.t_s = i * 1e-3;
          for (int t = 0; t < w.num_triangles; ++t)
            for (int c = 0; c < 3; ++c) w.tri_m[t][c].z() = 1e-4 * ((i / 17) % 3);
          tb->publish();
        }
        servo->tick(i, i * 1e-3);
        if (i % 17 == 0) rig.drain();
      }
      allocs = guard.count();
    }
    EXPECT_EQ(allocs, 0) << "mode " << mode_name(mode) << ", tool radius " << radius << ", friction " << mu
                         << ", jump limit " << jump << ", blend " << blend << ", shading " << shading;
    EXPECT_EQ(servo->counters().ticks, 10000);
  }
}

TEST(AllocationGuard, SeesAnAllocation) {
  test::AllocationGuard guard;
  auto p = std::make_unique<int>(3);
  EXPECT_EQ(guard.count(), 1);
}

TEST(ServoRunner, DefaultSpinWindowLeavesTheThreadASleepInEveryPeriod) {
  EXPECT_EQ(default_spin_us(1000.0), 100);
  EXPECT_EQ(default_spin_us(2000.0), 100);
  EXPECT_EQ(default_spin_us(5000.0), 50);
  EXPECT_EQ(default_spin_us(10000.0), 25);
  for (double rate : {500.0, 1000.0, 4000.0, 10000.0, 20000.0}) EXPECT_LE(default_spin_us(rate), 0.25e6 / rate) << rate;
}

TEST(LatencyHistogram, WideBucketsCoverAFrameLoopsLatencies) {
  // 1 us buckets (the servo's) end at 2 ms: a 60 Hz loop's 5-100 ms latencies would all be "max"
  LatencyHistogram servo;
  LatencyHistogram frames(100'000);
  for (int i = 0; i < 98; ++i) {
    servo.add(5'000'000);
    frames.add(5'000'000);
  }
  servo.add(103'000'000);
  frames.add(103'000'000);
  frames.add(300'000'000);  // past 200 ms: overflow, still the max
  EXPECT_EQ(servo.overflow(), 99);
  EXPECT_DOUBLE_EQ(servo.quantile_us(0.5), servo.max_us());
  EXPECT_DOUBLE_EQ(frames.range_us(), 200'000.0);
  EXPECT_DOUBLE_EQ(frames.quantile_us(0.5), 5'100.0);   // upper edge of the 5.0-5.1 ms bucket
  EXPECT_DOUBLE_EQ(frames.quantile_us(0.99), 103'100.0);
  EXPECT_EQ(frames.overflow(), 1);
  EXPECT_DOUBLE_EQ(frames.quantile_us(1.0), 300'000.0);
}

}  // namespace
}  // namespace palpate
