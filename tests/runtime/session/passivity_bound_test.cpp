// The coupling's passivity bound K < 2b/T in the closed loop: a stiff virtual wall held by the scripted hand
// (real mass and damping, force held between ticks) through the servo, in lockstep. A wall stiffer than the
// bound at 1 kHz but within it at 10 kHz settles at 10 kHz and rings up at 1 kHz; capped at 1 kHz it settles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/rates.h"
#include "core/scene.h"
#include "haptics/devices/scripted_device.h"
#include "haptics/servo/servo.h"
#include "support/haptic_fixtures.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/lockstep.h"

namespace palpate {
namespace {

constexpr double kWall_N_per_m = 10000.0;  // 2b/T = 4000 N/m at 1 kHz, 40000 N/m at 10 kHz for b = 2 Ns/m

// A scene asking for the stiff wall: the hand presses 1 cm into a rigid floor; only the rate limits the coupling.
Scene wall_scene() {
  Scene s;
  s.mode = InteractionMode::kTouch;
  s.hand.mass_kg = 0.12;
  s.hand.stiffness_N_per_m = 150.0;
  s.hand.damping_Ns_per_m = 2.0;
  s.device.coupling_N_per_m = kWall_N_per_m;
  s.device.coupling_damping_Ns_per_m = 0.0;
  s.device.max_stiffness_N_per_m = 1e5;
  s.device.max_force_N = 100.0;  // the clamp never acts: the coupling alone decides stability
  s.device.passivity = false;    // no energy observer either
  s.device.ramp_s = 0.0;
  s.trajectory = {{0.0, Vec3(0, 0, 0.004), false}, {0.2, Vec3(0, 0, -0.01), false}};
  return s;
}

struct WallRun {
  double coupling_N_per_m = 0;
  const char* bound = "";
  double early_swing_m = 0;  // peak-to-peak handle height over 0.3..0.8 s (after the impact)
  double late_swing_m = 0;   // ... over 3.5..4 s
  double wall_work_J = 0;    // work the coupling did on the handle over the last 3 s (> 0: the wall gave energy;
                             // a held sampled wall always gives a little, which the hand's damping must absorb)
};

// 4 s of the closed loop at rate_hz; capped: the coupling servo_params_for() gives, else the scene's as asked.
WallRun run_wall(double rate_hz, bool capped) {
  Scene scene = wall_scene();
  scene.rates.servo_hz = rate_hz;
  auto device_r = make_device(scene, "scripted");
  EXPECT_TRUE(device_r);
  Device& device = *device_r.value();
  ServoParams sp = servo_params_for(scene, device.specs());
  const CouplingLimit limit = coupling_limit(scene, device.specs());
  if (!capped) sp.coupling_N_per_m = scene.device.coupling_N_per_m;
  test::ServoRig<Device&> rig(sp, 64, scene.rates, device);
  test::publish_floor(rig.tb.get(), 0.1);

  WallRun r;
  r.coupling_N_per_m = sp.coupling_N_per_m;
  r.bound = limit.bound;
  double lo1 = 1, hi1 = -1, lo2 = 1, hi2 = -1;
  Vec3 prev_pos = Vec3::Zero(), prev_force = Vec3::Zero();
  run_lockstep(
      scene.rates, 4.0, [](int64_t, double) {},
      [&](int64_t i, double t) {
        rig.tick(i, t);
        const Vec3 pos = rig.servo->last_sample().tool_pos_m;
        const double z = pos.z();
        if (t >= 0.3 && t < 0.8) lo1 = std::min(lo1, z), hi1 = std::max(hi1, z);
        if (t >= 3.5) lo2 = std::min(lo2, z), hi2 = std::max(hi2, z);
        // the force sent last tick was held on the handle while it moved from prev_pos to pos
        if (t >= 1.0) r.wall_work_J += prev_force.dot(pos - prev_pos);
        prev_pos = pos;
        prev_force = rig.servo->last_sample().force_N;
      });
  r.early_swing_m = hi1 - lo1;
  r.late_swing_m = hi2 - lo2;
  return r;
}

// The scene at rate_hz.
Scene at_rate(Scene scene, double rate_hz) {
  scene.rates.servo_hz = rate_hz;
  return scene;
}

TEST(PassivityBound, CapFollowsTheRateAndTheDevicesDamping) {
  const Scene scene = wall_scene();
  DeviceSpecs specs;
  specs.max_stiffness_N_per_m = 1e5;
  specs.damping_Ns_per_m = 2.0;
  const CouplingLimit at1k = coupling_limit(at_rate(scene, 1000.0), specs);
  EXPECT_DOUBLE_EQ(at1k.passivity_max_N_per_m, CouplingLimit::kPassivityShare * 2.0 * 2.0 / 1e-3);
  EXPECT_DOUBLE_EQ(at1k.stiffness_N_per_m, at1k.passivity_max_N_per_m);
  EXPECT_STREQ(at1k.bound, "passivity 2b/T");
  // ten times the rate: ten times the bound, and the scene's own 10000 N/m is allowed
  const CouplingLimit at10k = coupling_limit(at_rate(scene, 10000.0), specs);
  EXPECT_DOUBLE_EQ(at10k.passivity_max_N_per_m, 10.0 * at1k.passivity_max_N_per_m);
  EXPECT_DOUBLE_EQ(at10k.stiffness_N_per_m, kWall_N_per_m);
  EXPECT_STREQ(at10k.bound, "scene coupling_N_per_m");
  // more device damping, more stiffness; the stiffness limits still apply
  specs.damping_Ns_per_m = 4.0;
  EXPECT_DOUBLE_EQ(coupling_limit(at_rate(scene, 1000.0), specs).stiffness_N_per_m, 2.0 * at1k.stiffness_N_per_m);
  specs.max_stiffness_N_per_m = 3000.0;
  EXPECT_STREQ(coupling_limit(at_rate(scene, 1000.0), specs).bound, "device max_stiffness_N_per_m");
  Scene low = scene;
  low.device.max_stiffness_N_per_m = 2500.0;
  EXPECT_DOUBLE_EQ(coupling_limit(at_rate(low, 1000.0), specs).stiffness_N_per_m, 2500.0);
  EXPECT_STREQ(coupling_limit(at_rate(low, 1000.0), specs).bound, "scene device.max_stiffness_N_per_m");
  // the scripted device's damping is the hand's; other drivers take device.damping_Ns_per_m
  auto scripted = make_device(scene, "scripted");
  ASSERT_TRUE(scripted);
  EXPECT_DOUBLE_EQ(scripted.value()->specs().damping_Ns_per_m, scene.hand.damping_Ns_per_m);
}

TEST(PassivityBound, WallStifferThanThe1kHzBoundSettlesAt10kHz) {
  const WallRun r = run_wall(10000.0, true);
  EXPECT_DOUBLE_EQ(r.coupling_N_per_m, kWall_N_per_m);  // not capped at this rate
  // the impact's ringing decays to nothing (measured: 0.15 mm after the impact, 4e-16 m at the end)
  EXPECT_LT(r.late_swing_m, 1e-3 * r.early_swing_m) << "early " << r.early_swing_m << " late " << r.late_swing_m;
  EXPECT_LT(r.late_swing_m, 1e-6);
  EXPECT_LT(r.wall_work_J, 1e-4);
}

TEST(PassivityBound, SameWallUncappedAt1kHzRingsUp) {
  const WallRun r = run_wall(1000.0, false);
  EXPECT_DOUBLE_EQ(r.coupling_N_per_m, kWall_N_per_m);
  // the oscillation grows until the handle bounces off the wall, and keeps bouncing: never decays (measured:
  // 2 mm peak to peak from 0.3 s to the end), fed by the wall (measured: 0.09 J over the last 3 s)
  EXPECT_GT(r.late_swing_m, 1e-3) << "early " << r.early_swing_m << " late " << r.late_swing_m;
  EXPECT_GT(r.late_swing_m, 0.9 * r.early_swing_m) << "early " << r.early_swing_m << " late " << r.late_swing_m;
  EXPECT_GT(r.wall_work_J, 1e-2);
}

TEST(PassivityBound, CappedAt1kHzTheWallSettlesAgain) {
  const WallRun r = run_wall(1000.0, true);
  EXPECT_LT(r.coupling_N_per_m, kWall_N_per_m);
  EXPECT_STREQ(r.bound, "passivity 2b/T");
  EXPECT_DOUBLE_EQ(r.coupling_N_per_m, CouplingLimit::kPassivityShare * 2.0 * 2.0 * 1000.0);
  // (measured: 0.48 mm after the impact, 2e-10 m at the end; the wall gave 1.4e-5 J, the hand took it)
  EXPECT_LT(r.late_swing_m, 1e-3 * r.early_swing_m) << "early " << r.early_swing_m << " late " << r.late_swing_m;
  EXPECT_LT(r.late_swing_m, 1e-6);
  EXPECT_LT(r.wall_work_J, 1e-4);
}

}  // namespace
}  // namespace palpate
