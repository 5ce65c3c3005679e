// Touch contact on hard geometry: a thin slab pushed through, a convex ridge crossed at an edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
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

TEST(GodObject, SlidingRoundACylinderFollowsTheSmoothNormalPastNinetyDegrees) {
  // half a cylinder of radius 2 cm about the y axis, 36 facets from the top (theta = 0, normal +z) round the
  // side (+x) to the bottom (theta = 180 deg), with smooth radial vertex normals; the tool slides round it 1 mm
  // deep. The side of the surface the contact holds to must turn with it: an entry-face normal would drop every
  // facet past 90 degrees and leave the proxy behind at the side.
  PathDevice dev;
  dev.specs_.max_force_N = 100;
  SpscQueue<HapticSample> q(4096);
  auto tb = std::make_unique<TripleBuffer<LocalModel>>();
  LocalModel& m = tb->write_buffer();
  const double r = 0.02, w = 0.02, pi = 3.14159265358979323846;
  auto at = [&](double th, double y) { return Vec3(r * std::sin(th), y, r * std::cos(th)); };
  auto radial = [](double th) { return Vec3(std::sin(th), 0, std::cos(th)); };
  for (int i = 0; i < 36; ++i) {
    const double t0 = pi * i / 36, t1 = pi * (i + 1) / 36;
    const Vec3 a = at(t0, -w), b = at(t1, -w), c = at(t1, w), d = at(t0, w);
    m.tri_ids[m.num_triangles] = 2 * i;
    m.tri_m[m.num_triangles] = {a, b, c};
    m.normal[m.num_triangles] = {radial(t0), radial(t1), radial(t1)};
    ++m.num_triangles;
    m.tri_ids[m.num_triangles] = 2 * i + 1;
    m.tri_m[m.num_triangles] = {a, c, d};
    m.normal[m.num_triangles] = {radial(t0), radial(t1), radial(t0)};
    ++m.num_triangles;
  }
  m.frame = 0;
  tb->publish();
  auto servo = make_servo(&dev, &q, tb.get());
  HapticSample sink;
  const double th0 = 10 * pi / 180;
  dev.pos_m = (r + 0.002) * radial(th0);
  servo->tick(0, 0);
  int64_t tick = 1, lost = 0, off = 0;
  // in through the surface, then round it to 170 degrees
  for (int i = 1; i <= 30; ++i, ++tick) {
    dev.pos_m = (r + 0.002 - 1e-4 * i) * radial(th0);
    servo->tick(tick, tick * 1e-3);
    while (q.try_pop(&sink)) {
    }
  }
  ASSERT_EQ(servo->last_sample().contact, ContactState::kTouch);
  double worst_m = 0.0;
  for (int i = 0; i <= 320; ++i, ++tick) {
    const double th = th0 + (160 * pi / 180) * i / 320;
    dev.pos_m = (r - 0.001) * radial(th);
    servo->tick(tick, tick * 1e-3);
    while (q.try_pop(&sink)) {
    }
    lost += servo->last_sample().contact != ContactState::kTouch ? 1 : 0;
    // the proxy is the surface point over the tool: on the radius (facet chords sag 19 um), at the tool's angle
    const Vec3 expect = r * radial(th);
    const double err = (servo->last_sample().proxy_pos_m - expect).norm();
    worst_m = std::max(worst_m, err);
    off += err > 1e-4 ? 1 : 0;
  }
  EXPECT_EQ(lost, 0);
  EXPECT_EQ(off, 0) << "worst " << worst_m << " m";
}

}  // namespace
}  // namespace palpate
