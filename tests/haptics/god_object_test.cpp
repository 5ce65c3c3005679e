// Touch contact on hard geometry: a thin slab pushed through, a convex ridge crossed at an edge.
#include <gtest/gtest.h>

#include <memory>

#include "haptics/servo.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

using PathDevice = test::FixedDevice;
using test::add_quad;

std::unique_ptr<Servo> make_servo(PathDevice* dev, SpscQueue<HapticSample>* q, TripleBuffer<LocalModel>* tb) {
  ServoParams p;
  p.coupling_N_per_m = 300;
  p.coupling_damping_Ns_per_m = 0;
  p.ramp_s = 0;
  p.passivity = false;
  p.force_model = ForceModel::kStaticSurface;
  return std::make_unique<Servo>(p, dev, q, tb);
}

TEST(GodObject, ToolPushedThroughAThinSlabStaysOnTheEntryFace) {
  // a 2 mm slab: top z = +1 mm facing up, bottom z = -1 mm facing down
  PathDevice dev;
  dev.specs_.max_force_N = 100;
  SpscQueue<HapticSample> q(4096);
  auto tb = std::make_unique<TripleBuffer<LocalModel>>();
  LocalModel& m = tb->write_buffer();
  const double h = 0.05, t = 0.001;
  add_quad(&m, Vec3(-h, -h, t), Vec3(h, -h, t), Vec3(h, h, t), Vec3(-h, h, t));
  add_quad(&m, Vec3(-h, -h, -t), Vec3(-h, h, -t), Vec3(h, h, -t), Vec3(h, -h, -t));
  m.frame = 0;
  tb->publish();
  auto servo = make_servo(&dev, &q, tb.get());
  HapticSample sink;
  for (int i = 0; i <= 100; ++i) {
    dev.pos_m = Vec3(0.003, 0.002, 0.004 - 1e-4 * i);  // from 4 mm above down to 6 mm below
    servo->tick(i, i * 1e-3);
    while (q.try_pop(&sink)) {
    }
    if (dev.pos_m.z() < t - 1e-9) {
      ASSERT_EQ(servo->last_sample().contact, ContactState::kTouch) << "tick " << i;
      EXPECT_NEAR(servo->last_sample().proxy_pos_m.z(), t, 1e-12) << "tick " << i;
      EXPECT_NEAR(dev.force_N.z(), 300 * (t - dev.pos_m.z()), 1e-9) << "tick " << i;
    }
  }
}

TEST(GodObject, SlidingAcrossAConvexRidgeKeepsContact) {
  // a roof: two faces meeting along the y axis at z = 0, sloping down 30 degrees to each side
  PathDevice dev;
  SpscQueue<HapticSample> q(4096);
  auto tb = std::make_unique<TripleBuffer<LocalModel>>();
  LocalModel& m = tb->write_buffer();
  const double w = 0.05, drop = w * std::tan(0.5235987755982988);
  add_quad(&m, Vec3(-w, -w, -drop), Vec3(0, -w, 0), Vec3(0, w, 0), Vec3(-w, w, -drop));
  add_quad(&m, Vec3(0, -w, 0), Vec3(w, -w, -drop), Vec3(w, w, -drop), Vec3(0, w, 0));
  m.frame = 0;
  tb->publish();
  auto servo = make_servo(&dev, &q, tb.get());
  HapticSample sink;
  dev.pos_m = Vec3(-0.01, 0, 0.01);
  servo->tick(0, 0);
  int in_contact = 0;
  for (int i = 1; i <= 200; ++i) {
    // 1 mm under the roof line, from x = -10 mm to +10 mm
    const double x = -0.01 + 1e-4 * i;
    dev.pos_m = Vec3(x, 0.0, -std::abs(x) * std::tan(0.5235987755982988) - 0.001);
    servo->tick(i, i * 1e-3);
    while (q.try_pop(&sink)) {
    }
    in_contact += servo->last_sample().contact == ContactState::kTouch;
    if (i > 1) {
      EXPECT_EQ(servo->last_sample().contact, ContactState::kTouch) << "x " << x;
      EXPECT_GT(dev.force_N.z(), 0.0) << "x " << x;
      EXPECT_LE((servo->last_sample().proxy_pos_m - dev.pos_m).norm(), 0.001 + 1e-9) << "x " << x;
    }
  }
  EXPECT_EQ(in_contact, 200);
}

}  // namespace
}  // namespace palpate
