#include "haptics/devices/scripted_device.h"

#include <gtest/gtest.h>

#include <cmath>

namespace palpate {
namespace {

std::vector<Keyframe> keys() {
  return {{0.0, Vec3(0, 0, 0), false}, {1.0, Vec3(0.1, 0, 0), true}, {2.0, Vec3(0.1, 0.2, 0), false}};
}

TEST(ScriptedDevice, TargetInterpolatesPositionsAndHoldsButtons) {
  ScriptedDevice d(DeviceSpecs{}, HandSpec{}, keys());
  Vec3 p;
  bool b = true;
  d.target(0.5, &p, &b);
  EXPECT_NEAR((p - Vec3(0.05, 0, 0)).norm(), 0, 1e-15);
  EXPECT_FALSE(b);
  d.target(1.5, &p, &b);
  EXPECT_NEAR((p - Vec3(0.1, 0.1, 0)).norm(), 0, 1e-15);
  EXPECT_TRUE(b);
  d.target(9.0, &p, &b);
  EXPECT_EQ(p, Vec3(0.1, 0.2, 0));
  EXPECT_FALSE(b);
}

TEST(ScriptedDevice, HandSettlesAtTargetPlusForceOverStiffness) {
  HandSpec hand;
  hand.mass_kg = 0.1;
  hand.stiffness_N_per_m = 200;
  hand.damping_Ns_per_m = 6;
  ScriptedDevice d(DeviceSpecs{}, hand, {{0.0, Vec3(0.01, 0.02, 0.03), false}});
  d.write_force(Vec3(0, 0, 1.0));  // the device pushes the handle up with 1 N
  DevicePose pose;
  for (int i = 1; i <= 5000; ++i) d.read(i * 1e-3, &pose);
  EXPECT_NEAR(pose.pos_m.z(), 0.03 + 1.0 / 200.0, 1e-6);
  EXPECT_NEAR(pose.pos_m.x(), 0.01, 1e-9);
}

TEST(ScriptedDevice, UndampedHandOscillatesAtItsNaturalPeriod) {
  HandSpec hand;
  hand.mass_kg = 0.1;
  hand.stiffness_N_per_m = 100;
  hand.damping_Ns_per_m = 0;
  ScriptedDevice d(DeviceSpecs{}, hand, {{0.0, Vec3::Zero(), false}});
  d.write_force(Vec3(1.0, 0, 0));  // a step force: x(t) = F/k (1 - cos(w t))
  DevicePose pose;
  const double w = std::sqrt(100 / 0.1);
  double worst = 0.0;
  for (int i = 1; i <= 1000; ++i) {
    d.read(i * 1e-3, &pose);
    worst = std::max(worst, std::abs(pose.pos_m.x() - 0.01 * (1 - std::cos(w * i * 1e-3))));
  }
  EXPECT_LT(worst, 0.01 * 0.05);  // within 5% of the amplitude at 1 kHz
}

}  // namespace
}  // namespace palpate
