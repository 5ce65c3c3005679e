// Coulomb friction in the god-object on a flat face: breakaway at mu_s F_n, sliding at mu_d F_n, a slow stroke
// without stick-slip chatter.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "haptics/servo/servo.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

constexpr double kK = 300.0, kMuS = 0.6, kMuD = 0.4, kDepth = 0.002;

struct Stroke {
  double normal_N = 0.0;         // F_n while stuck, before the stroke
  double breakaway_N = 0.0;      // largest force across before the proxy first moved
  double sliding_min_N = INFINITY, sliding_max_N = 0.0;  // force across while sliding (after 50 ms)
  double max_step_excess_N = 0.0;  // largest tick-to-tick step beyond k |device step| while sliding
  int stuck_ticks_while_sliding = 0;
};

// the tool pressed kDepth into the floor z = 0, then stroked along +x at speed_m_per_s for 0.6 s
Stroke stroke(double radius, double speed_m_per_s, double trail_drop_m, int ticks = 900) {
  ServoParams p = test::static_surface_params(kK);
  p.tool_radius_m = radius;
  p.friction.static_coefficient = kMuS;
  p.friction.dynamic_coefficient = kMuD;
  p.friction.trail_drop_m = trail_drop_m;
  test::FloorRig rig(p, false);
  Stroke s;
  HapticSample prev;
  bool slipped = false;
  int slip_tick = -1;
  for (int i = 0; i < ticks; ++i) {
    const double z = radius + 0.002 - std::min(1.0, i / 100.0) * (0.002 + kDepth);
    const double x = i < 300 ? 0.0 : speed_m_per_s * (i - 300) * 1e-3;
    rig.dev.pos_m = Vec3(x, 0.001, z);
    rig.tick(i);
    const HapticSample& now = rig.servo->last_sample();
    EXPECT_EQ(now.contact, i < 100 ? now.contact : ContactState::kTouch) << i;
    if (i == 299) s.normal_N = now.force_N.z();
    if (i >= 300) {
      const double across = -now.force_N.x();
      const bool moved = (now.proxy_pos_m - prev.proxy_pos_m).norm() > 1e-12;
      if (!slipped) s.breakaway_N = std::max(s.breakaway_N, across);
      if (moved && !slipped) {
        slipped = true;
        slip_tick = i;
      }
      if (slipped && i > slip_tick + 50) {
        s.sliding_min_N = std::min(s.sliding_min_N, across);
        s.sliding_max_N = std::max(s.sliding_max_N, across);
        s.stuck_ticks_while_sliding += !moved;
      }
      if (slipped) {
        const double dtool = (now.tool_pos_m - prev.tool_pos_m).norm();
        s.max_step_excess_N = std::max(s.max_step_excess_N, (now.force_N - prev.force_N).norm() - kK * dtool);
      }
    }
    prev = now;
  }
  EXPECT_TRUE(slipped);
  return s;
}

TEST(Friction, BreakawayAtStaticAndSlidingAtDynamicCoefficientOnAFlatFace) {
  for (double radius : {0.0, 0.005}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    const Stroke s = stroke(radius, 0.01, 0.02 / kK);
    EXPECT_NEAR(s.normal_N, kK * kDepth, 1e-6);  // 0.6 N
    EXPECT_NEAR(s.breakaway_N, kMuS * s.normal_N, 0.05 * kMuS * s.normal_N);
    EXPECT_NEAR(s.sliding_min_N, kMuD * s.normal_N, 0.05 * kMuD * s.normal_N);
    EXPECT_NEAR(s.sliding_max_N, kMuD * s.normal_N, 0.05 * kMuD * s.normal_N);
  }
}

TEST(Friction, SlowStrokeSlidesWithoutStickSlip) {
  // 2 mm/s: the device moves 2 um a tick; sliding the proxy moves every tick and the force steps by no more than
  // the device's step explains plus 0.02 N (also at breakaway, which comes down to the sliding level gradually)
  for (double radius : {0.0, 0.005}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    const Stroke s = stroke(radius, 0.002, 0.02 / kK, 1300);  // breakaway after 0.6 s, then 0.4 s sliding
    EXPECT_EQ(s.stuck_ticks_while_sliding, 0);
    EXPECT_LE(s.max_step_excess_N, 0.02 + 1e-9);
  }
}

TEST(Friction, NoCoefficientsIsFrictionless) {
  test::ServoRig<> rig(test::static_surface_params(kK));
  test::publish_floor(rig.tb.get());
  for (int i = 0; i < 400; ++i) {
    rig.dev.pos_m = Vec3(i < 200 ? 0.0 : 1e-5 * (i - 200), 0.001, 0.002 - std::min(1.0, i / 100.0) * 0.004);
    rig.tick(i);
  }
  EXPECT_NEAR(rig.dev.force_N.x(), 0.0, 1e-9);
  EXPECT_NEAR(rig.dev.force_N.z(), kK * kDepth, 1e-9);
}

TEST(Friction, StrokedOutOfADentTheProxyTrailsWithoutJumps) {
  // a dent 2 mm deep and 6 mm wide (what the lattice makes under a pressed tool) in a floor of 2 mm facets; the
  // 5 mm sphere pressed 1.5 mm into its bottom, then stroked 8 mm out of it at 20 mm/s: stuck, breaking away and
  // sliding up the dent's wall, the force steps by no more than the device's step explains plus 0.02 N (a cone
  // taken across the normal at the device once moved the proxy along a crease of the facets by 0.3 mm in a tick).
  // A point tool, which rolls over the convex facet edges of the dent's rim in bounded steps, does the same.
  for (double radius : {0.0, 0.005}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    ServoParams p = test::static_surface_params(kK);
    p.tool_radius_m = radius;
    p.friction.static_coefficient = kMuS;
    p.friction.dynamic_coefficient = kMuD;
    p.friction.trail_drop_m = 0.02 / kK;
    test::ServoRig<> rig(p);
    rig.dev.specs_.max_force_N = 100;
    LocalModel& m = rig.tb->write_buffer();
    m.num_triangles = 0;
    const double cell = 0.002, half = 0.015;
    auto z = [](double x, double y) { return -0.002 * std::exp(-(x * x + y * y) / (0.003 * 0.003)); };
    for (double x = -half; x < half - 1e-9; x += cell)
      for (double y = -half; y < half - 1e-9; y += cell) {
        auto at = [&](double u, double v) { return Vec3(u, v, z(u, v)); };
        test::add_quad(&m, at(x, y), at(x + cell, y), at(x + cell, y + cell), at(x, y + cell));
      }
    m.frame = 0;
    rig.tb->publish();
    HapticSample prev;
    double worst_excess_N = 0.0, travel_m = 0.0;
    int contact = 0;
    for (int i = 0; i < 700; ++i) {
      const double x = 0.0003 + (i < 300 ? 0.0 : 2e-5 * (i - 300));
      rig.dev.pos_m = Vec3(x, 0.0004, radius - 0.002 + 0.002 - std::min(1.0, i / 100.0) * 0.0035);
      rig.tick(i);
      const HapticSample& now = rig.servo->last_sample();
      contact += now.contact == ContactState::kTouch;
      if (i > 120) {
        const double dtool = (now.tool_pos_m - prev.tool_pos_m).norm();
        worst_excess_N = std::max(worst_excess_N, (now.force_N - prev.force_N).norm() - kK * dtool);
        travel_m += (now.proxy_pos_m - prev.proxy_pos_m).norm();
      }
      prev = now;
    }
    EXPECT_GT(contact, 550);
    EXPECT_GT(travel_m, 0.002);  // it did break away and slide
    EXPECT_LE(worst_excess_N, 0.02 + 1e-9);
  }
}

TEST(Friction, BreakawayFollowsTheNormalForceOnATiltedFaceInAnyDirection) {
  // a face turned 20 degrees off the axes, pressed 1 and 3 mm deep, then pulled slowly across it in three directions
  // of its plane: the proxy holds until the force across it reaches mu_s times the force along its normal, measured
  // in the face's own frame, whatever the depth and the direction
  const Vec3 n = Vec3(0.25, -0.2, 1.0).normalized();
  const Vec3 e1 = n.cross(Vec3::UnitX()).normalized(), e2 = n.cross(e1);
  for (double depth : {0.001, 0.003}) {
    for (double dir_deg : {0.0, 130.0, 250.0}) {
      SCOPED_TRACE("depth " + std::to_string(depth) + " m, direction " + std::to_string(dir_deg) + " deg");
      const double a = dir_deg * 3.14159265358979323846 / 180.0;
      const Vec3 u = std::cos(a) * e1 + std::sin(a) * e2;
      ServoParams p = test::static_surface_params(kK);
      p.friction.static_coefficient = kMuS;
      p.friction.dynamic_coefficient = kMuD;
      test::ServoRig<> rig(p);
      rig.dev.specs_.max_force_N = 100;
      LocalModel& m = rig.tb->write_buffer();
      m.num_triangles = 0;
      const double h = 0.05;
      test::add_quad(&m, -h * e1 - h * e2, h * e1 - h * e2, h * e1 + h * e2, -h * e1 + h * e2);
      m.frame = 0;
      rig.tb->publish();
      HapticSample prev;
      double breakaway = 0.0, normal = 0.0;
      bool slipped = false;
      for (int i = 0; i < 700 && !slipped; ++i) {
        const double in = 0.002 - std::min(1.0, i / 100.0) * (0.002 + depth);
        const double across = i < 200 ? 0.0 : 1e-5 * (i - 200);  // 10 mm/s
        rig.dev.pos_m = in * n + across * u;
        rig.tick(i);
        const HapticSample& now = rig.servo->last_sample();
        if (i >= 200) {
          if ((now.proxy_pos_m - prev.proxy_pos_m).norm() > 1e-12) {
            slipped = true;
          } else {
            breakaway = std::max(breakaway, (now.force_N - now.force_N.dot(n) * n).norm());
            normal = now.force_N.dot(n);
          }
        }
        prev = now;
      }
      ASSERT_TRUE(slipped);
      EXPECT_NEAR(normal, kK * depth, 1e-6);
      EXPECT_NEAR(breakaway, kMuS * normal, 0.03 * kMuS * normal);
    }
  }
}

}  // namespace
}  // namespace palpate
