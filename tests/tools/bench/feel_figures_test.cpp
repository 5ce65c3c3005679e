// bench feel's figures on traces whose answers are known: a still press, a buzz, a release step, a slide.
#include <gtest/gtest.h>

#include <cmath>

#include "tools/bench/feel_figures.h"

namespace palpate {
namespace {

constexpr double kPi = 3.14159265358979323846;

// a device pressing 2 mm into a surface at z = 0 over 0.4 s and holding: F = k (0 - z) along z
std::vector<FeelTick> press(int ticks, double k) {
  std::vector<FeelTick> tr(static_cast<std::size_t>(ticks));
  for (int i = 0; i < ticks; ++i) {
    const double z = -0.002 * std::min(1.0, i / 400.0);
    tr[i].tool_m = Vec3(0, 0, z);
    tr[i].force_N = Vec3(0, 0, -k * z);
    tr[i].contact = ContactState::kTouch;
  }
  return tr;
}

TEST(FeelFigures, SmoothPressIsExplainedByTheDeviceAndHasNoBuzz) {
  const FeelSettings s;
  const FeelFigures f = feel_figures(press(1000, s.coupling_N_per_m), s);
  EXPECT_EQ(f.contact_ticks, 1000);
  EXPECT_NEAR(f.max_step_N, s.coupling_N_per_m * 0.002 / 400, 1e-12);  // 1.5 mN a tick
  EXPECT_EQ(f.excess_over, 0);
  EXPECT_LT(f.max_excess_N, 1e-12);
  EXPECT_EQ(f.lateral_flips, 0);
  EXPECT_LT(f.buzz_share, 0.01);
  // the device pushes into the surface against the force: the hand does work on it (negative into the hand)
  EXPECT_NEAR(f.energy_into_hand_J, -0.5 * s.coupling_N_per_m * 0.002 * 0.002, 2e-6);
}

TEST(FeelFigures, ALateralBuzzOnAStillDeviceIsCaught) {
  const FeelSettings s;
  auto tr = press(1000, s.coupling_N_per_m);
  for (int i = 0; i < 1000; ++i) {
    tr[i].tool_m = Vec3(0, 0, -0.002);  // held still, 0.6 N
    tr[i].force_N = Vec3(i >= 500 ? (i % 2 ? 0.04 : -0.04) : 0.0, 0, 0.6);  // from 0.5 s a 500 Hz buzz
  }
  const FeelFigures f = feel_figures(tr, s);
  EXPECT_EQ(f.steps_over, 0);     // 0.08 N steps stay under the 0.1 N threshold ...
  EXPECT_EQ(f.excess_over, 500);  // ... but the device is still: none is explained (the first, 0.04 N, from 0)
  EXPECT_NEAR(f.max_excess_N, 0.08, 1e-12);
  EXPECT_GE(f.lateral_flips, 490);
  EXPECT_GT(f.buzz_share, 0.5);
}

TEST(FeelFigures, AReleaseStepIsAnEventNotSteadyContact) {
  const FeelSettings s;
  auto tr = press(600, s.coupling_N_per_m);
  tr[0].contact = ContactState::kFree;  // the touch begins on tick 1
  tr.resize(700);
  for (int i = 600; i < 700; ++i) tr[i] = FeelTick{Vec3(0, 0, -0.002), Vec3::Zero(), ContactState::kFree};
  const FeelFigures f = feel_figures(tr, s);
  const auto& rel = f.events[static_cast<int>(FeelEvent::kRelease)];
  EXPECT_EQ(rel.count, 1);
  EXPECT_NEAR(rel.max_step_N, 0.6, 1e-12);
  EXPECT_NEAR(rel.max_excess_N, 0.6, 1e-12);
  EXPECT_EQ(f.events[static_cast<int>(FeelEvent::kEntry)].count, 1);
  EXPECT_LT(f.max_step_N, 0.01);  // the release is not a steady-contact step
}

TEST(FeelFigures, RippleWhileSlidingIsPeakToPeakOverTheMean) {
  // sliding at 10 mm/s with 1 N and a 5 % peak-to-peak ripple at 200 Hz (the 20 ms trend keeps almost none of it)
  const FeelSettings s;
  std::vector<FeelTick> tr(1000);
  for (int i = 0; i < 1000; ++i) {
    tr[i].tool_m = Vec3(1e-5 * i, 0, -0.003);
    tr[i].force_N = Vec3(0, 0, 1.0 + 0.025 * std::sin(2 * kPi * 200 * i * 1e-3));
    tr[i].contact = ContactState::kTouch;
  }
  const FeelFigures f = feel_figures(tr, s);
  EXPECT_GT(f.sliding_ticks, 900);
  EXPECT_NEAR(f.ripple, 0.05, 0.005);
  EXPECT_GT(f.buzz_share, 0.99);
}

}  // namespace
}  // namespace palpate
