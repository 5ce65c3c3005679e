// The multirate contact model: the lattice's compliance at a point, and the servo's between-frame force.
#include "haptics/contact_compliance.h"

#include <gtest/gtest.h>

#include <memory>

#include "haptics/servo.h"
#include "support/haptic_fixtures.h"

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
  const bool ok = cc.compute(lat, w, true, &c);
  if (ok) EXPECT_TRUE(c.allFinite());
  else EXPECT_EQ(c, Mat3::Constant(7.0));
}

using StillDevice = test::FixedDevice;

TEST(Servo, LocalModelGivesTheSeriesSpringOfCouplingAndObject) {
  // floor z = 0 whose contact point yields with compliance c along z: pressing d deep, the device feels the
  // series stiffness k_c k_o / (k_c + k_o) instead of k_c against a rigid (stale) surface
  StillDevice dev;
  SpscQueue<HapticSample> q(64);
  auto tb = std::make_unique<TripleBuffer<LocalModel>>();
  const double k_c = 300, k_o = 100, d = 0.004;
  LocalModel& m = tb->write_buffer();
  test::add_quad(&m, Vec3(-0.1, -0.1, 0), Vec3(0.1, -0.1, 0), Vec3(0.1, 0.1, 0), Vec3(-0.1, 0.1, 0));
  m.has_contact_model = true;
  m.contact_p0_m = Vec3::Zero();
  m.compliance_m_per_N = Mat3::Identity() / k_o;
  m.model_radius_m = 0.01;
  m.frame = 0;
  tb->publish();
  for (ForceModel fm : {ForceModel::kStaticSurface, ForceModel::kLocalModel}) {
    ServoParams p;
    p.coupling_N_per_m = k_c;
    p.coupling_damping_Ns_per_m = 0;
    p.ramp_s = 0;
    p.passivity = false;
    p.force_model = fm;
    Servo servo(p, &dev, &q, tb.get());
    dev.pos_m = Vec3(0, 0, 0.01);
    servo.tick(0, 0.0);
    dev.pos_m = Vec3(0, 0, -d);
    servo.tick(1, 0.001);
    servo.tick(2, 0.002);
    const double want = fm == ForceModel::kLocalModel ? k_c * k_o / (k_c + k_o) * d : k_c * d;
    EXPECT_NEAR(dev.force_N.z(), want, 1e-9) << static_cast<int>(fm);
  }
}

}  // namespace
}  // namespace palpate
