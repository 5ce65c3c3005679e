// The lattice's static compliance at a point (used by the servo between frames): analytic cases and the
// singular ones (nothing fixed, a piece cut free) reported, never returned as a number.
#include "sim/contact_compliance.h"

#include <gtest/gtest.h>

namespace palpate {
namespace {

// One free node at the origin held by six axis springs to fixed nodes: K = 2 k I, so C = I / (2k).
Lattice star(double k) {
  Lattice lat;
  lat.rest_m = {Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
  lat.x_m = lat.rest_m;
  lat.v_m_per_s.assign(7, Vec3::Zero());
  lat.mass_kg.assign(7, 1.0);
  lat.fixed = {0, 1, 1, 1, 1, 1, 1};
  for (int32_t j = 1; j < 7; ++j) {
    Spring s;
    s.a = 0;
    s.b = j;
    s.rest_m = 1.0;
    s.k_N_per_m = k;
    lat.springs.push_back(s);
  }
  return lat;
}

TEST(ContactCompliance, StarOfSpringsHasAnalyticCompliance) {
  const Lattice lat = star(50.0);
  PointWeights w;
  w.count = 1;
  w.node[0] = 0;
  w.weight[0] = 1.0;
  ContactCompliance cc;
  Mat3 c;
  ASSERT_TRUE(cc.compute(lat, w, true, &c));
  EXPECT_LT((c - Mat3::Identity() / 100.0).norm(), 1e-12);
  // a point shared half with a fixed node feels half the force: C scales by 1/4
  w.count = 2;
  w.weight[0] = 0.5;
  w.node[1] = 3;
  w.weight[1] = 0.5;
  ASSERT_TRUE(cc.compute(lat, w, false, &c));
  EXPECT_LT((c - Mat3::Identity() / 400.0).norm(), 1e-12);
}

TEST(ContactCompliance, FreeFloatingLatticeIsReportedNotNaN) {
  Lattice lat = star(50.0);
  lat.fixed.assign(7, 0);
  PointWeights w;
  w.count = 1;
  w.node[0] = 0;
  w.weight[0] = 1.0;
  ContactCompliance cc;
  Mat3 c = Mat3::Constant(7.0);
  // nothing holds it: no compliance exists (not "rigid", C = 0, nor round-off garbage), and c is untouched
  EXPECT_FALSE(cc.compute(lat, w, true, &c));
  EXPECT_EQ(c, Mat3::Constant(7.0));
  // held again: the same solver answers
  EXPECT_TRUE(cc.compute(star(50.0), w, true, &c));
  EXPECT_LT((c - Mat3::Identity() / 100.0).norm(), 1e-12);
}

TEST(ContactCompliance, PieceCutFreeOfItsFixedNodesIsReported) {
  // the star plus a pair of nodes joined only to each other (a piece cut free): singular, whatever the point
  Lattice lat = star(50.0);
  lat.rest_m.push_back(Vec3(3, 0, 0));
  lat.rest_m.push_back(Vec3(4, 0, 0));
  lat.x_m = lat.rest_m;
  lat.v_m_per_s.assign(9, Vec3::Zero());
  lat.mass_kg.assign(9, 1.0);
  lat.fixed.push_back(0);
  lat.fixed.push_back(0);
  Spring s;
  s.a = 7;
  s.b = 8;
  s.rest_m = 1.0;
  s.k_N_per_m = 50.0;
  lat.springs.push_back(s);
  PointWeights w;
  w.count = 1;
  w.node[0] = 0;
  w.weight[0] = 1.0;
  ContactCompliance cc;
  Mat3 c = Mat3::Constant(7.0);
  EXPECT_FALSE(cc.compute(lat, w, true, &c));
  EXPECT_EQ(c, Mat3::Constant(7.0));
}


}  // namespace
}  // namespace palpate
