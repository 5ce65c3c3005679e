// The passivity controller against the classic sampled-wall instability: a stiff virtual wall held by a loose hand.
#include "haptics/force/passivity_guard.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "haptics/devices/scripted_device.h"
#include "haptics/servo/servo.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

// a rigid floor as the servo sees it when the sim publishes nothing new (stalled or rigid)
using test::publish_floor;

struct WallRun {
  double early_swing_m = 0, late_swing_m = 0, max_force_N = 0;
  int64_t activations = 0;
};

// 4 s of a hand with almost no damping pressing 1 cm into a 700 N/m wall (the device's stiffness limit);
// Colgate's bound K < 2b/T = 2 * 0.05 / 1e-3 = 100 N/m is far exceeded.
WallRun run_wall(bool passivity) {
  DeviceSpecs specs;
  HandSpec hand;
  hand.mass_kg = 0.12;
  hand.stiffness_N_per_m = 150;
  hand.damping_Ns_per_m = 0.05;
  ServoParams p;
  p.mode = InteractionMode::kTouch;
  p.coupling_N_per_m = 700;
  p.coupling_damping_Ns_per_m = 0;
  p.passivity = passivity;
  p.ramp_s = 0;
  p.jump_limit_N_per_tick = 0;
  const std::vector<Keyframe> press = {{0.0, Vec3(0, 0, 0.004), false}, {0.2, Vec3(0, 0, -0.01), false}};
  test::ServoRig<ScriptedDevice> rig(p, 16, test::kTestRates, specs, hand, press);  // at 1 kHz
  publish_floor(rig.tb.get(), 0.1);
  WallRun r;
  double lo1 = 1, hi1 = -1, lo2 = 1, hi2 = -1;
  for (int i = 0; i < 4000; ++i) {
    rig.tick(i);
    const double z = rig.servo->last_sample().tool_pos_m.z();
    if (i >= 1000 && i < 1500) lo1 = std::min(lo1, z), hi1 = std::max(hi1, z);
    if (i >= 3500) lo2 = std::min(lo2, z), hi2 = std::max(hi2, z);
    r.max_force_N = std::max(r.max_force_N, rig.servo->last_sample().force_N.norm());
  }
  r.early_swing_m = hi1 - lo1;
  r.late_swing_m = hi2 - lo2;
  r.activations = rig.servo->counters().passivity_activations;
  return r;
}

TEST(Passivity, WithoutTheControllerTheSampledWallOscillationGrows) {
  const WallRun r = run_wall(false);
  EXPECT_GT(r.late_swing_m, 2.0 * r.early_swing_m) << "early " << r.early_swing_m << " late " << r.late_swing_m;
  EXPECT_GT(r.late_swing_m, 0.002);
}

TEST(Passivity, TheControllerKeepsTheHandleSettledAndForceClamped) {
  const WallRun r = run_wall(true);
  EXPECT_LE(r.late_swing_m, std::max(1.1 * r.early_swing_m, 2e-4)) << "early " << r.early_swing_m << " late " << r.late_swing_m;
  EXPECT_LE(r.max_force_N, DeviceSpecs{}.max_force_N + 1e-12);
  EXPECT_GT(r.activations, 0);
}

TEST(PassivityGuard, LeavesAPassiveSpringAloneAndDampsAnActiveOne) {
  // a spring whose force is evaluated at the end of each step (F = -k x, an implicit, passive rendering)
  // over a prescribed cycle: the observer stays positive and never acts
  PassivityGuard passive;
  const double k = 500, dt = 1e-3;
  double x_prev = 0.0;
  for (int i = 1; i <= 1000; ++i) {
    const double x = 0.01 * std::sin(6.283185307 * i * dt);
    passive.sent(Vec3(-k * x, 0, 0));
    passive.filter(Vec3(-k * x, 0, 0), Vec3(x - x_prev, 0, 0), dt);
    x_prev = x;
  }
  EXPECT_EQ(passive.activations(), 0);
  EXPECT_GE(passive.energy_J(), 0.0);
  // an "environment" that pushes along the motion creates energy: the guard brakes it
  PassivityGuard active;
  Vec3 out = Vec3::Zero();
  for (int i = 0; i < 100; ++i) out = active.filter(Vec3(1.0, 0, 0), Vec3(1e-4, 0, 0), dt);
  EXPECT_GT(active.activations(), 90);
  EXPECT_LT(out.x(), 1.0);
}

TEST(PassivityGuard, ItsDampingSwitchesOnAndOffNoFasterThanTheStatedStep) {
  // an environment that pushes along the motion for 50 ticks, then a passive one: the damping the controller adds
  // changes by at most 0.02 N a tick (without the bound it comes in and leaves in one tick), and over the run it
  // still dissipates what the active part put in
  const double dt = 1e-3, v = 0.05;
  for (double step : {0.0, 0.02}) {
    PassivityGuard g;
    double largest = 0.0, last_damp = 0.0;
    for (int i = 0; i < 300; ++i) {
      const Vec3 env = i < 50 ? Vec3(1.0, 0, 0) : Vec3(-0.2, 0, 0);
      const Vec3 out = g.filter(env, Vec3(v * dt, 0, 0), dt, step);
      const double damp = out.x() - env.x();
      largest = std::max(largest, std::abs(damp - last_damp));
      last_damp = damp;
    }
    if (step > 0.0) {
      EXPECT_LE(largest, step + 1e-12);
      EXPECT_GE(g.energy_J(), -0.02 * v * dt);  // passive again by the end, within a tick's bounded damping
    } else {
      EXPECT_GT(largest, 0.5);  // unbounded: the whole damping force at once
    }
    EXPECT_GT(g.activations(), 40);
  }
}

}  // namespace
}  // namespace palpate
