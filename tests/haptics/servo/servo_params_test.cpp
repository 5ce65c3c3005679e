// One owner per parameter (core/scene.h): a ServoParams nobody filled in is the servo a default scene asks for (every field a scene
// key sets has the scene's default, so neither can drift from the other), and each of those keys reaches the servo
// through servo_params_for().
#include "haptics/servo/servo_params.h"

#include <gtest/gtest.h>

namespace palpate {
namespace {

// a device that limits nothing: the coupling is the scene's
DeviceSpecs unlimited() {
  DeviceSpecs d;
  d.max_stiffness_N_per_m = 1e12;
  d.damping_Ns_per_m = 1e9;
  return d;
}

TEST(ServoParams, TheDefaultsAreTheDefaultScenesAndEveryKeyReachesTheServo) {
  const ServoParams plain;
  const ServoParams scene = servo_params_for(scene_defaults(), unlimited());
  EXPECT_EQ(plain.mode, scene.mode);
  EXPECT_EQ(plain.coupling_N_per_m, scene.coupling_N_per_m);
  EXPECT_EQ(plain.coupling_damping_Ns_per_m, scene.coupling_damping_Ns_per_m);
  EXPECT_EQ(plain.grab_radius_m, scene.grab_radius_m);
  EXPECT_EQ(plain.passivity, scene.passivity);
  EXPECT_EQ(plain.ramp_s, scene.ramp_s);
  EXPECT_EQ(plain.blade_length_m, scene.blade_length_m);
  EXPECT_EQ(plain.cut_resistance_Ns_per_m, scene.cut_resistance_Ns_per_m);
  EXPECT_EQ(plain.tool_radius_m, scene.tool_radius_m);
  EXPECT_EQ(plain.friction.static_coefficient, scene.friction.static_coefficient);
  EXPECT_EQ(plain.friction.dynamic_coefficient, scene.friction.dynamic_coefficient);
  EXPECT_EQ(plain.jump_limit_N_per_tick, scene.jump_limit_N_per_tick);
  EXPECT_EQ(plain.force_shading_deg, scene.force_shading_deg);
  EXPECT_EQ(plain.predict_grab, scene.predict_grab);
  EXPECT_GT(plain.jump_limit_N_per_tick, 0.0) << "the scene limits force steps by default; so does a servo";

  // each key changed in the scene changes the servo's
  Scene s = scene_defaults();
  s.mode = InteractionMode::kPull;
  s.device.coupling_N_per_m = 123.0;
  s.device.coupling_damping_Ns_per_m = 0.7;
  s.grab_radius_m = 0.011;
  s.device.passivity = !s.device.passivity;
  s.device.ramp_s = 0.37;
  s.blade_length_m = 0.021;
  s.cut_resistance_Ns_per_m = 3.1;
  s.device.sphere_tool = true;
  s.device.tool_radius_m = 0.004;
  s.static_friction = 0.6;
  s.dynamic_friction = 0.4;
  s.device.jump_limit_N_per_tick = 0.05;
  s.device.force_shading_deg = 40.0;
  s.lattice.integrator = IntegratorKind::kImplicitEuler;
  const ServoParams p = servo_params_for(s, unlimited());
  EXPECT_EQ(p.mode, InteractionMode::kPull);
  EXPECT_EQ(p.coupling_N_per_m, 123.0);
  EXPECT_EQ(p.coupling_damping_Ns_per_m, 0.7);
  EXPECT_EQ(p.grab_radius_m, 0.011);
  EXPECT_EQ(p.passivity, s.device.passivity);
  EXPECT_EQ(p.ramp_s, 0.37);
  EXPECT_EQ(p.blade_length_m, 0.021);
  EXPECT_EQ(p.cut_resistance_Ns_per_m, 3.1);
  EXPECT_EQ(p.tool_radius_m, 0.004);
  EXPECT_EQ(p.friction.static_coefficient, 0.6);
  EXPECT_EQ(p.friction.dynamic_coefficient, 0.4);
  EXPECT_EQ(p.jump_limit_N_per_tick, 0.05);
  EXPECT_EQ(p.force_shading_deg, 40.0);
  EXPECT_NE(p.predict_grab, scene.predict_grab);
  // derived: after breakaway the friction force falls no faster than the jump limit
  EXPECT_DOUBLE_EQ(p.friction.trail_drop_m, 0.05 / 123.0);
  // the device's limits and the passivity bound cap the coupling
  DeviceSpecs stiff = unlimited();
  stiff.max_stiffness_N_per_m = 50.0;
  EXPECT_EQ(servo_params_for(s, stiff).coupling_N_per_m, 50.0);
  EXPECT_STREQ(coupling_limit(s, stiff).bound, "device max_stiffness_N_per_m");
}

}  // namespace
}  // namespace palpate
