// The multirate contact model: the servo's between-frame force from the compliance the sim publishes.
#include <gtest/gtest.h>

#include <memory>

#include "haptics/servo/servo.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

using StillDevice = test::FixedDevice;

TEST(Servo, LocalModelGivesTheSeriesSpringOfCouplingAndObject) {
  // floor z = 0 whose contact point yields with compliance c along z: pressing d deep, the device feels the
  // series stiffness k_c k_o / (k_c + k_o) instead of k_c against a rigid (stale) surface
  test::ServoRig<StillDevice> rig(ServoParams{}, 64);  // one servo a force model, over one device and surface
  const double k_c = 300, k_o = 100, d = 0.004;
  LocalModel& m = rig.tb->write_buffer();
  test::add_quad(&m, Vec3(-0.1, -0.1, 0), Vec3(0.1, -0.1, 0), Vec3(0.1, 0.1, 0), Vec3(-0.1, 0.1, 0));
  m.has_contact_model = true;
  m.contact_p0_m = Vec3::Zero();
  m.compliance_m_per_N = Mat3::Identity() / k_o;
  m.model_radius_m = 0.01;
  m.frame = 0;
  rig.tb->publish();
  for (ForceModel fm : {ForceModel::kStaticSurface, ForceModel::kLocalModel}) {
    ServoParams p;
    p.coupling_N_per_m = k_c;
    p.coupling_damping_Ns_per_m = 0;
    p.ramp_s = 0;
    p.jump_limit_N_per_tick = 0;  // the first contact tick's force itself, not its ramp
    p.passivity = false;
    p.force_model = fm;
    rig.servo = rig.make_servo(p);  // at 1 kHz
    rig.dev.pos_m = Vec3(0, 0, 0.01);
    rig.tick(0);
    rig.dev.pos_m = Vec3(0, 0, -d);
    rig.tick(1);
    rig.tick(2);
    const double want = fm == ForceModel::kLocalModel ? k_c * k_o / (k_c + k_o) * d : k_c * d;
    EXPECT_NEAR(rig.dev.force_N.z(), want, 1e-9) << static_cast<int>(fm);
  }
}

}  // namespace
}  // namespace palpate
