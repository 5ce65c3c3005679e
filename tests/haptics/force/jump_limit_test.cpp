// The jump limit: an entry, a release and a grab reach the hand at most jump_limit_N_per_tick a tick, steady
// contact is left as it is, and with no limit the steps are whole.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "haptics/servo/servo.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

constexpr double kK = 300.0, kRate = 0.02;

struct Steps {
  double largest_N = 0.0;        // largest tick-to-tick force step
  double pressed_N = 0.0;        // force while held 2 mm in (steady contact)
  int ticks_to_zero = 0;         // ticks from the release until the force is zero
};

// touch: pressed 2 mm into the floor, held, then the tool leaves 5 mm in one tick
Steps release(double rate) {
  ServoParams p = test::static_surface_params(kK);
  p.jump_limit_N_per_tick = rate;
  test::FloorRig rig(p, false);
  Steps s;
  Vec3 prev = Vec3::Zero();
  for (int i = 0; i < 400; ++i) {
    rig.dev.pos_m = Vec3(0.001, 0.002, i < 300 ? 0.002 - std::min(1.0, i / 100.0) * 0.004 : 0.005);
    rig.tick(i);
    if (i > 100) s.largest_N = std::max(s.largest_N, (rig.dev.force_N - prev).norm());
    if (i == 299) s.pressed_N = rig.dev.force_N.z();
    if (i >= 300 && rig.dev.force_N.norm() > 0.0) s.ticks_to_zero = i - 299;
    prev = rig.dev.force_N;
  }
  return s;
}

TEST(JumpLimit, ReleaseComesDownAtTheStatedRate) {
  const Steps limited = release(kRate);
  EXPECT_NEAR(limited.pressed_N, kK * 0.002, 1e-9);      // steady contact: the force as computed
  EXPECT_LE(limited.largest_N, kRate + 1e-12);           // 0.6 N let go at 0.02 N a tick ...
  EXPECT_EQ(limited.ticks_to_zero, 29);                  // ... 0.58 N on the release tick, zero on the 30th
  const Steps whole = release(0.0);
  EXPECT_NEAR(whole.largest_N, kK * 0.002, 1e-9);        // no limit: the 0.6 N step in one tick
  EXPECT_EQ(whole.ticks_to_zero, 0);
}

TEST(JumpLimit, GrabStartsAtTheStatedRate) {
  // pull: the button pressed 4 mm above the floor grabs the point under the tool: k 4 mm = 1.2 N at once unlimited
  for (double rate : {kRate, 0.0}) {
    ServoParams p = test::static_surface_params(kK);
    p.mode = InteractionMode::kPull;
    p.jump_limit_N_per_tick = rate;
    test::FloorRig rig(p, false);
    double largest = 0.0;
    Vec3 prev = Vec3::Zero();
    for (int i = 0; i < 200; ++i) {
      rig.dev.pos_m = Vec3(0.001, 0.002, 0.004);
      rig.dev.buttons = i >= 20 ? 1u : 0u;
      rig.tick(i);
      largest = std::max(largest, (rig.dev.force_N - prev).norm());
      prev = rig.dev.force_N;
    }
    EXPECT_NEAR(rig.dev.force_N.z(), -kK * 0.004, 1e-9);  // held: the whole force in the end
    EXPECT_NEAR(largest, rate > 0 ? rate : kK * 0.004, 1e-9);
  }
}

TEST(JumpLimit, ContactEntryComesInAtTheStatedRate) {
  // touch: the tool comes down at 0.2 m/s (0.2 mm a tick) and enters the floor 50 um deep on its first contact tick,
  // with the coupling's damping b_c = 0.5 N s/m: unlimited, k 50 um + b_c v = 0.115 N in that tick, 0.055 N beyond
  // what the device's step explains (k |dx| + b_c |dv|); limited, the entry brings the rate and no step goes beyond
  // the explained one by more than the rate
  for (double rate : {kRate, 0.0}) {
    ServoParams p = test::static_surface_params(kK);
    p.coupling_damping_Ns_per_m = 0.5;
    p.jump_limit_N_per_tick = rate;
    test::FloorRig rig(p, false);
    double worst_excess_N = 0.0, entry_step_N = 0.0;
    Vec3 prev_force = Vec3::Zero(), prev_pos = Vec3::Zero(), prev_step = Vec3::Zero();
    for (int i = 0; i < 200; ++i) {
      // from 11.95 mm above (the velocity estimate settles on the way), 0.2 mm a tick, down to 2 mm deep and held
      rig.dev.pos_m = Vec3(0.001, 0.002, std::max(-0.002, 0.01195 - 0.0002 * i));
      rig.tick(i);
      const Vec3 step = rig.dev.pos_m - prev_pos;
      if (i > 0) {
        const double explained = kK * step.norm() + 0.5 * (step - prev_step).norm() / 1e-3;
        worst_excess_N = std::max(worst_excess_N, (rig.dev.force_N - prev_force).norm() - explained);
      }
      if (rig.servo->last_sample().contact == ContactState::kTouch && prev_force.isZero())
        entry_step_N = rig.dev.force_N.norm();
      prev_force = rig.dev.force_N;
      prev_step = step;
      prev_pos = rig.dev.pos_m;
    }
    EXPECT_NEAR(rig.dev.force_N.z(), kK * 0.002, 1e-9);  // held: the whole force in the end
    if (rate > 0) {
      EXPECT_NEAR(entry_step_N, rate, 1e-12);
      EXPECT_LE(worst_excess_N, rate + 1e-9);
    } else {
      EXPECT_NEAR(entry_step_N, kK * 50e-6 + 0.5 * 0.2, 1e-6);
      EXPECT_GT(worst_excess_N, 0.05);
    }
  }
}

}  // namespace
}  // namespace palpate
