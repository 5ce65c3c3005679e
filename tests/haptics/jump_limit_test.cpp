// The jump limit: a release and a grab reach the hand at most jump_limit_N_per_tick a tick, steady contact is
// left as it is, and with no limit the steps are whole.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "haptics/servo.h"
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
  test::FixedDevice dev;
  dev.specs_.max_force_N = 100;
  SpscQueue<HapticSample> q(4096);
  auto tb = std::make_unique<TripleBuffer<LocalModel>>();
  test::publish_floor(tb.get());
  ServoParams p = test::static_surface_params(kK);
  p.jump_limit_N_per_tick = rate;
  Servo servo(p, test::kTestRates, &dev, &q, tb.get());
  Steps s;
  HapticSample sink;
  Vec3 prev = Vec3::Zero();
  for (int i = 0; i < 400; ++i) {
    dev.pos_m = Vec3(0.001, 0.002, i < 300 ? 0.002 - std::min(1.0, i / 100.0) * 0.004 : 0.005);
    servo.tick(i, i * 1e-3);
    while (q.try_pop(&sink)) {
    }
    if (i > 100) s.largest_N = std::max(s.largest_N, (dev.force_N - prev).norm());
    if (i == 299) s.pressed_N = dev.force_N.z();
    if (i >= 300 && dev.force_N.norm() > 0.0) s.ticks_to_zero = i - 299;
    prev = dev.force_N;
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
    test::FixedDevice dev;
    dev.specs_.max_force_N = 100;
    SpscQueue<HapticSample> q(4096);
    auto tb = std::make_unique<TripleBuffer<LocalModel>>();
    test::publish_floor(tb.get());
    ServoParams p = test::static_surface_params(kK);
    p.mode = InteractionMode::kPull;
    p.jump_limit_N_per_tick = rate;
    Servo servo(p, test::kTestRates, &dev, &q, tb.get());
    HapticSample sink;
    double largest = 0.0;
    Vec3 prev = Vec3::Zero();
    for (int i = 0; i < 200; ++i) {
      dev.pos_m = Vec3(0.001, 0.002, 0.004);
      dev.buttons = i >= 20 ? 1u : 0u;
      servo.tick(i, i * 1e-3);
      while (q.try_pop(&sink)) {
      }
      largest = std::max(largest, (dev.force_N - prev).norm());
      prev = dev.force_N;
    }
    EXPECT_NEAR(dev.force_N.z(), -kK * 0.004, 1e-9);  // held: the whole force in the end
    EXPECT_NEAR(largest, rate > 0 ? rate : kK * 0.004, 1e-9);
  }
}

}  // namespace
}  // namespace palpate
