// Touch contact on hard geometry: a thin slab pushed through, a convex ridge crossed at an edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "haptics/force/proxy_solver.h"
#include "haptics/servo/servo.h"
#include "haptics/force/triangle_queries.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

using PathDevice = test::FixedDevice;
using test::add_quad;

// A touch servo of coupling 300 N/m on the static surface: no damping, ramp or passivity guard.
ServoParams touch_params(double tool_radius_m = 0.0, double jump_limit_N_per_tick = 0.0) {
  ServoParams p;
  p.jump_limit_N_per_tick = jump_limit_N_per_tick;
  p.tool_radius_m = tool_radius_m;
  p.coupling_N_per_m = 300;
  p.coupling_damping_Ns_per_m = 0;
  p.ramp_s = 0;
  p.passivity = false;
  p.force_model = ForceModel::kStaticSurface;
  return p;
}

TEST(GodObject, ToolPushedThroughAThinSlabStaysOnTheEntryFace) {
  // a 2 mm slab: top z = +1 mm facing up, bottom z = -1 mm facing down
  test::ServoRig<PathDevice> rig(touch_params());
  rig.dev.specs_.max_force_N = 100;
  LocalModel& m = rig.tb->write_buffer();
  const double h = 0.05, t = 0.001;
  add_quad(&m, Vec3(-h, -h, t), Vec3(h, -h, t), Vec3(h, h, t), Vec3(-h, h, t));
  add_quad(&m, Vec3(-h, -h, -t), Vec3(-h, h, -t), Vec3(h, h, -t), Vec3(h, -h, -t));
  m.frame = 0;
  rig.tb->publish();
  for (int i = 0; i <= 100; ++i) {
    rig.dev.pos_m = Vec3(0.003, 0.002, 0.004 - 1e-4 * i);  // from 4 mm above down to 6 mm below
    rig.tick(i);
    if (rig.dev.pos_m.z() < t - 1e-9) {
      ASSERT_EQ(rig.servo->last_sample().contact, ContactState::kTouch) << "tick " << i;
      EXPECT_NEAR(rig.servo->last_sample().proxy_pos_m.z(), t, 1e-12) << "tick " << i;
      EXPECT_NEAR(rig.dev.force_N.z(), 300 * (t - rig.dev.pos_m.z()), 1e-9) << "tick " << i;
    }
  }
}

// A sheet whose vertex normals point to its other side (an open sheet's back, or faces back to back whose normals
// averaged the wrong way, as in a scan or an exported double-sided part): a sphere pressed onto it from above and
// stroked across stays above it. The side the contact holds to is where the sphere's centre is, never the normals'
// side (taken from the normals, the next tick passed the sheet's faces over as its far side and the sphere fell
// through: 7 mm and a 2.1 N step on assimp's regr01.obj).
TEST(GodObject, ASphereOnASheetWhoseNormalsPointAwayStaysOnItsSide) {
  const double r = 0.003;
  ServoParams p = test::static_surface_params(300);
  p.tool_radius_m = r;
  test::FloorRig rig(p, false);
  // the rig's floor z = 0 (wound +z) again, its vertex normals turned to its underside
  LocalModel& m = rig.tb->write_buffer();
  m.num_triangles = 0;
  add_quad(&m, Vec3(-0.05, -0.05, 0), Vec3(0.05, -0.05, 0), Vec3(0.05, 0.05, 0), Vec3(-0.05, 0.05, 0));
  for (int i = 0; i < m.num_triangles; ++i) m.normal[i] = {Vec3(0.1, 0, -1).normalized(), -Vec3::UnitZ(), -Vec3::UnitZ()};
  m.frame = 1;
  rig.tb->publish();
  int touched = 0;
  for (int i = 0; i <= 600; ++i) {
    // down from 6 mm above to 2 mm into the sheet in 100 ticks, then 20 mm across
    const double z = std::max(-0.002, 0.006 - 8e-5 * i), x = i > 100 ? 4e-5 * (i - 100) : 0.0;
    rig.dev.pos_m = Vec3(x, 0.001, z);
    rig.tick(i);
    const HapticSample& s = rig.servo->last_sample();
    if (touched == 0 && s.contact != ContactState::kTouch) continue;
    // once touched, the tool stays within the sphere's reach of the sheet: the contact holds
    ASSERT_EQ(s.contact, ContactState::kTouch) << "tick " << i << ": contact lost with the tool under the sheet";
    ++touched;
    ASSERT_GE(s.proxy_pos_m.z(), r - 1e-6) << "tick " << i << ": the sphere's centre went under the sheet";
    ASSERT_GE(rig.dev.force_N.z(), 0.0) << "tick " << i << ": the force pulls the hand into the sheet";
  }
  EXPECT_GT(touched, 400);
}

TEST(GodObject, SlidingAcrossAConvexRidgeKeepsContact) {
  // a roof: two faces meeting along the y axis at z = 0, sloping down 30 degrees to each side
  test::ServoRig<PathDevice> rig(touch_params());
  LocalModel& m = rig.tb->write_buffer();
  const double w = 0.05, drop = w * std::tan(0.5235987755982988);
  add_quad(&m, Vec3(-w, -w, -drop), Vec3(0, -w, 0), Vec3(0, w, 0), Vec3(-w, w, -drop));
  add_quad(&m, Vec3(0, -w, 0), Vec3(w, -w, -drop), Vec3(w, w, -drop), Vec3(0, w, 0));
  m.frame = 0;
  rig.tb->publish();
  rig.dev.pos_m = Vec3(-0.01, 0, 0.01);
  rig.tick(0);
  int in_contact = 0;
  for (int i = 1; i <= 200; ++i) {
    // 1 mm under the roof line, from x = -10 mm to +10 mm
    const double x = -0.01 + 1e-4 * i;
    rig.dev.pos_m = Vec3(x, 0.0, -std::abs(x) * std::tan(0.5235987755982988) - 0.001);
    rig.tick(i);
    in_contact += rig.servo->last_sample().contact == ContactState::kTouch;
    if (i > 1) {
      EXPECT_EQ(rig.servo->last_sample().contact, ContactState::kTouch) << "x " << x;
      EXPECT_GT(rig.dev.force_N.z(), 0.0) << "x " << x;
      // a god-object holds to a face while the device's projection lies on it, so it is never further from the
      // device than the face's nearest point (1 mm deep on a face; at most the ridge line's distance near it)
      const double ridge = std::hypot(x, std::abs(x) * std::tan(0.5235987755982988) + 0.001);
      EXPECT_LE((rig.servo->last_sample().proxy_pos_m - rig.dev.pos_m).norm(), std::max(0.001, ridge) + 1e-9)
          << "x " << x;
    }
  }
  EXPECT_EQ(in_contact, 200);
}

TEST(GodObject, SlidingRoundACylinderFollowsTheSmoothNormalPastNinetyDegrees) {
  // half a cylinder of radius 2 cm about the y axis, 36 facets from the top (theta = 0, normal +z) round the
  // side (+x) to the bottom (theta = 180 deg), with smooth radial vertex normals; the tool slides round it 1 mm
  // deep. The side of the surface the contact holds to must turn with it: an entry-face normal would drop every
  // facet past 90 degrees and leave the proxy behind at the side.
  test::ServoRig<PathDevice> rig(touch_params());
  rig.dev.specs_.max_force_N = 100;
  LocalModel& m = rig.tb->write_buffer();
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
  rig.tb->publish();
  const double th0 = 10 * pi / 180;
  rig.dev.pos_m = (r + 0.002) * radial(th0);
  rig.tick(0);
  int64_t tick = 1, lost = 0, off = 0;
  // in through the surface, then round it to 170 degrees
  for (int i = 1; i <= 30; ++i, ++tick) {
    rig.dev.pos_m = (r + 0.002 - 1e-4 * i) * radial(th0);
    rig.tick(tick);
  }
  ASSERT_EQ(rig.servo->last_sample().contact, ContactState::kTouch);
  double worst_m = 0.0;
  for (int i = 0; i <= 320; ++i, ++tick) {
    const double th = th0 + (160 * pi / 180) * i / 320;
    rig.dev.pos_m = (r - 0.001) * radial(th);
    rig.tick(tick);
    lost += rig.servo->last_sample().contact != ContactState::kTouch ? 1 : 0;
    // the proxy is the surface point over the tool: on the radius (facet chords sag 19 um), at the tool's angle
    const Vec3 expect = r * radial(th);
    const double err = (rig.servo->last_sample().proxy_pos_m - expect).norm();
    worst_m = std::max(worst_m, err);
    off += err > 1e-4 ? 1 : 0;
  }
  EXPECT_EQ(lost, 0);
  EXPECT_EQ(off, 0) << "worst " << worst_m << " m";
}

// Distance from p to the nearest triangle of the patch.
double distance_to_patch(const LocalModel& m, const Vec3& p) {
  double best = INFINITY;
  for (int i = 0; i < m.num_triangles; ++i) {
    Vec3 b;
    const auto& t = m.tri_m[i];
    best = std::min(best, (closest_point_on_triangle(p, t[0], t[1], t[2], &b) - p).norm());
  }
  return best;
}

TEST(SphereTool, PressedOnAFlatFaceItsCentreRestsOneRadiusAbove) {
  // floor z = 0; a 5 mm sphere: contact starts when the centre comes within 5 mm (before it crosses the face), and
  // however deep the device goes the centre stays at z = r, right above the device; a point tool's proxy is on
  // the face itself
  const double r = 0.005;
  test::ServoRig<PathDevice> rig(touch_params(r));
  rig.dev.specs_.max_force_N = 100;
  test::publish_floor(rig.tb.get());
  Servo* const sphere = rig.servo.get();
  const std::unique_ptr<Servo> point = rig.make_servo(touch_params());  // over the same device
  for (int i = 0; i <= 150; ++i) {
    rig.dev.pos_m = Vec3(0.003, -0.002, 0.010 - 1e-4 * i);  // from 10 mm above down to 5 mm below
    sphere->tick(i, i * 1e-3);
    const HapticSample s = sphere->last_sample();
    point->tick(i, i * 1e-3);
    rig.drain();
    const double z = rig.dev.pos_m.z();
    if (z > r + 1e-9) {
      EXPECT_EQ(s.contact, ContactState::kFree) << "z " << z;
      continue;
    }
    if (z > r - 1e-9) continue;  // touching
    ASSERT_EQ(s.contact, ContactState::kTouch) << "z " << z;
    EXPECT_NEAR((s.proxy_pos_m - Vec3(0.003, -0.002, r)).norm(), 0.0, 1e-12) << "z " << z;
    EXPECT_NEAR(s.force_N.z(), 300 * (r - z), 1e-9) << "z " << z;
    // the contact point is the face point under the centre
    EXPECT_GE(s.contact_tri, 10);
    if (z < -1e-9) {
      EXPECT_NEAR(point->last_sample().proxy_pos_m.z(), 0.0, 1e-12) << "z " << z;
      EXPECT_NEAR(point->last_sample().force_N.z(), -300 * z, 1e-9) << "z " << z;
    }
  }
  // lifted until the sphere no longer reaches the face: free
  rig.dev.pos_m = Vec3(0.003, -0.002, r + 1e-4);
  sphere->tick(151, 0.151);
  EXPECT_EQ(sphere->last_sample().contact, ContactState::kFree);
  EXPECT_EQ(rig.dev.force_N, Vec3::Zero());
}

TEST(SphereTool, PushedThroughAThinSlabStaysOnTheEntryFace) {
  // the 2 mm slab of the point-tool test and a 3 mm sphere: pushed 6 mm under the slab, the centre stays 3 mm
  // above its top face
  const double h = 0.05, t = 0.001, r = 0.003;
  test::ServoRig<PathDevice> rig(touch_params(r));
  rig.dev.specs_.max_force_N = 100;
  LocalModel& m = rig.tb->write_buffer();
  add_quad(&m, Vec3(-h, -h, t), Vec3(h, -h, t), Vec3(h, h, t), Vec3(-h, h, t));
  add_quad(&m, Vec3(-h, -h, -t), Vec3(-h, h, -t), Vec3(h, h, -t), Vec3(h, -h, -t));
  m.frame = 0;
  rig.tb->publish();
  for (int i = 0; i <= 130; ++i) {
    rig.dev.pos_m = Vec3(0.003, 0.002, 0.007 - 1e-4 * i);  // from 7 mm above down to 6 mm below
    rig.tick(i);
    if (rig.dev.pos_m.z() < t + r - 1e-9) {
      ASSERT_EQ(rig.servo->last_sample().contact, ContactState::kTouch) << "tick " << i;
      EXPECT_NEAR(rig.servo->last_sample().proxy_pos_m.z(), t + r, 1e-12) << "tick " << i;
    }
  }
}

TEST(SphereTool, RollsOverAConvexRidgeOneRadiusFromTheSurface) {
  // the 30-degree roof of the point-tool test, the device 1 mm under the roof line from x = -10 mm to +10 mm,
  // a 4 mm sphere: in contact all the way, its centre exactly one radius from the roof (never inside it), and it
  // rolls over the ridge line (its centre passes r above it) instead of jumping from one face's offset to the
  // other's (a jump of 1.22 r; the spring drags it over the top in steps well below that)
  const double w = 0.05, slope = 0.5235987755982988, drop = w * std::tan(slope), r = 0.004;
  test::ServoRig<PathDevice> rig(touch_params(r, 0.02));  // the jump limit bounds the proxy's step
  rig.dev.specs_.max_force_N = 100;
  LocalModel& m = rig.tb->write_buffer();
  add_quad(&m, Vec3(-w, -w, -drop), Vec3(0, -w, 0), Vec3(0, w, 0), Vec3(-w, w, -drop));
  add_quad(&m, Vec3(0, -w, 0), Vec3(w, -w, -drop), Vec3(w, w, -drop), Vec3(0, w, 0));
  m.frame = 0;
  rig.tb->publish();
  rig.dev.pos_m = Vec3(-0.01, 0, 0.01);
  rig.tick(0);
  int in_contact = 0;
  double worst_gap = 0.0, largest_step = 0.0, highest = -1.0;
  Vec3 prev_centre = Vec3::Constant(NAN);
  for (int i = 1; i <= 200; ++i) {
    const double x = -0.01 + 1e-4 * i;
    rig.dev.pos_m = Vec3(x, 0.0, -std::abs(x) * std::tan(slope) - 0.001);
    rig.tick(i);
    const HapticSample& s = rig.servo->last_sample();
    in_contact += s.contact == ContactState::kTouch;
    worst_gap = std::max(worst_gap, std::abs(distance_to_patch(rig.tb->read(), s.proxy_pos_m) - r));
    if (i > 1) largest_step = std::max(largest_step, (s.proxy_pos_m - prev_centre).norm());
    prev_centre = s.proxy_pos_m;
    highest = std::max(highest, s.proxy_pos_m.z());
    EXPECT_GT(rig.dev.force_N.z(), 0.0) << "x " << x;
  }
  EXPECT_EQ(in_contact, 200);
  EXPECT_LT(worst_gap, 1e-9);
  EXPECT_GT(highest, 0.99 * r);
  EXPECT_LE(highest, r + 1e-12);
  EXPECT_LT(largest_step, 0.7 * r);
  // past the ridge it rests on the right face, r along its normal from the face point under it
  EXPECT_GT(prev_centre.x(), 0.0);
}

TEST(SphereTool, InAConcaveCornerItTouchesBothFaces) {
  // a V-shaped groove: two faces at 45 degrees meeting along the y axis at z = 0, a 3 mm sphere pushed straight
  // down into it sits with its centre r / sin 45 above the groove line, touching both faces
  const double w = 0.03, r = 0.003;
  test::ServoRig<PathDevice> rig(touch_params(r));
  rig.dev.specs_.max_force_N = 100;
  LocalModel& m = rig.tb->write_buffer();
  add_quad(&m, Vec3(-w, -w, w), Vec3(0, -w, 0), Vec3(0, w, 0), Vec3(-w, w, w));
  add_quad(&m, Vec3(0, -w, 0), Vec3(w, -w, w), Vec3(w, w, w), Vec3(0, w, 0));
  m.frame = 0;
  rig.tb->publish();
  for (int i = 0; i <= 120; ++i) {
    rig.dev.pos_m = Vec3(0.0005, 0.0, 0.010 - 1e-4 * i);
    rig.tick(i);
  }
  const HapticSample& s = rig.servo->last_sample();
  ASSERT_EQ(s.contact, ContactState::kTouch);
  EXPECT_NEAR(distance_to_patch(rig.tb->read(), s.proxy_pos_m), r, 1e-6);
  EXPECT_NEAR(s.proxy_pos_m.z(), r * std::sqrt(2.0), 1e-5);
  EXPECT_NEAR(s.proxy_pos_m.x(), 0.0, 1e-5);
}

// A fold of a scanned surface: a face the tool's own path enters from its front, but turned more than 120 degrees
// from the contact's side (the test the far side of a thin part is passed over by). It stops the move as any face
// does: before, the god-object went through it to the goal beneath.
TEST(GodObject, AFoldTurnedAgainstTheContactSideStillStopsThePath) {
  LocalModel m;
  const double h = 0.01;
  add_quad(&m, Vec3(-h, -h, 0), Vec3(h, -h, 0), Vec3(h, h, 0), Vec3(-h, h, 0));  // faces +z
  const Vec3 side = Vec3(0.0, 0.8, -0.6);  // 127 degrees from the face's normal
  int active = -1;
  const Vec3 c = god_object_move(m, Vec3(0.001, 0.002, 0.005), Vec3(0.001, 0.002, -0.005), 1e-6, side, &active);
  EXPECT_GE(active, 1);
  EXPECT_GE(c.z(), -1e-12);
  EXPECT_NEAR(c.x(), 0.001, 1e-9);
}

// Rolling over a convex facet edge with the path bounded (the jump limit): the centre that the bound stopped past the
// edge drops the shortest way onto the next face, not toward a goal deep beneath it. With the goal almost parallel to
// the next face, falling toward it carried the proxy 0.8 mm along that face in one tick (a 0.4 N click on a coarse
// ball); now the move is the bound and the drop, under 0.25 mm.
TEST(GodObject, ABoundedMovePastAConvexEdgeDropsOntoTheNextFaceNotTowardTheGoal) {
  LocalModel m;
  const double w = 0.01, slope = std::tan(20.0 * 3.14159265358979 / 180.0);
  add_quad(&m, Vec3(-w, -w, 0), Vec3(0, -w, 0), Vec3(0, w, 0), Vec3(-w, w, 0));                   // flat, x < 0
  add_quad(&m, Vec3(0, -w, 0), Vec3(w, -w, -w * slope), Vec3(w, w, -w * slope), Vec3(0, w, 0));   // 20 degrees down
  const Vec3 from(-1e-4, 0.0, 1e-6), goal(0.003, 0.0, -0.0012);
  int active = -1;
  const Vec3 c = god_object_move(m, from, goal, 1e-6, Vec3::UnitZ(), &active, 2e-4);
  EXPECT_GE(active, 1);
  EXPECT_LT((c - from).norm(), 2.5e-4);
  EXPECT_GT(c.x(), 0.0);                                 // past the edge
  EXPECT_NEAR(c.z(), -c.x() * slope, 2e-6);              // on the next face
}

// A free tool that went where the patch does not reach (a dense mesh's patch cut short, a fast hand) and through a
// face there: the next patch that covers it judges its whole path from where it was last seen outside, and the touch
// begins on the outside. Judged from the last tick only, the tool was already under the face: free, inside, for good.
TEST(GodObject, AToolThatPassedUnseenIsCaughtByTheNextPatchThatSeesItsPath) {
  test::ServoRig<PathDevice> rig(touch_params());
  rig.dev.specs_.max_force_N = 100;
  auto publish = [&](const Vec3& at, int64_t frame) {
    LocalModel& m = rig.tb->write_buffer();
    m = LocalModel{};
    const double h = 0.004;
    add_quad(&m, at + Vec3(-h, -h, 0), at + Vec3(h, -h, 0), at + Vec3(h, h, 0), at + Vec3(-h, h, 0));
    m.cover_lo_m = m.cover_hi_m = at;
    m.cover_radius_m = h;
    m.frame = frame;
    rig.tb->publish();
  };
  publish(Vec3::Zero(), 0);  // the patch round the origin only
  const Vec3 x(0.02, 0.0, 0.0);
  for (int i = 0; i <= 40; ++i) {
    rig.dev.pos_m = x + Vec3(0.0, 0.0, 0.003 - 1.5e-4 * i);  // down through the surface at x = 20 mm, unseen
    rig.tick(i);
    EXPECT_EQ(rig.servo->last_sample().contact, ContactState::kFree);
  }
  publish(x, 1);  // the next frame's patch covers the tool
  rig.tick(41);
  EXPECT_EQ(rig.servo->last_sample().contact, ContactState::kTouch);
  EXPECT_GE(rig.servo->last_sample().god_pos_m.z(), 0.0);
  EXPECT_GT(rig.dev.force_N.z(), 0.0);
}

TEST(GodObject, APointIsFeltWhereItsGodObjectIsHeldWhenTheSmoothNormalNamesAnotherFace) {
  // a floor z = 0 whose smooth normals lean 108 degrees from its faces' (an open sheet's fold, where vertex normals
  // average faces turned every way; regr01.obj), and 5 mm from the press a wall facing +x. The god-object is held on
  // the floor; among the faces facing the side its smooth normal names, the wall is the nearest to it. A point was felt
  // from that wall's point, 5 mm away, until the side changed: a 1.5 N jump here, 0.13 N on regr01.obj. It is felt from
  // where its god-object is held, every tick
  test::ServoRig<PathDevice> rig(touch_params());
  LocalModel& m = rig.tb->write_buffer();
  const double w = 0.05;
  add_quad(&m, Vec3(-w, -w, 0), Vec3(0.005, -w, 0), Vec3(0.005, w, 0), Vec3(-w, w, 0));
  const Vec3 fold = Vec3(0.9, 0.0, -0.3).normalized();
  for (int t = 0; t < m.num_triangles; ++t) m.normal[t] = {fold, fold, fold};
  add_quad(&m, Vec3(0.005, -w, 0), Vec3(0.005, -w, -0.01), Vec3(0.005, w, -0.01), Vec3(0.005, w, 0));
  ASSERT_NEAR(m.normal[m.num_triangles - 1][0].x(), 1.0, 1e-12);
  m.frame = 0;
  rig.tb->publish();
  int touching = 0;
  Vec3 last_force = Vec3::Zero(), last_tool = Vec3::Zero();
  for (int i = 0; i <= 100; ++i) {
    rig.dev.pos_m = Vec3(0.0, 0.0, 0.002 - 0.004 * std::min(1.0, i / 50.0));
    rig.tick(i);
    const HapticSample& s = rig.servo->last_sample();
    if (s.contact == ContactState::kTouch) {
      ++touching;
      EXPECT_NEAR(s.god_pos_m.z(), 0.0, 1e-5) << "tick " << i;  // held on the floor
      EXPECT_LE((s.proxy_pos_m - s.god_pos_m).norm(), 1e-5) << "tick " << i;
      if (touching > 1) {  // (after the entry's own tick)
        EXPECT_LE((rig.dev.force_N - last_force).norm(), 300.0 * (rig.dev.pos_m - last_tool).norm() + 1e-3)
            << "tick " << i;
      }
    }
    last_force = rig.dev.force_N;
    last_tool = rig.dev.pos_m;
  }
  EXPECT_GT(touching, 40);
  EXPECT_NEAR(rig.dev.force_N.z(), 300.0 * 0.002, 1e-3);
}

}  // namespace
}  // namespace palpate
