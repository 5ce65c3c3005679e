#include "haptics/servo/servo_params.h"

#include <utility>

namespace palpate {

CouplingLimit coupling_limit(const Scene& scene, const DeviceSpecs& device) {
  const double rate_hz = scene.rates.servo_hz;
  CouplingLimit c;
  c.scene_N_per_m = scene.device.coupling_N_per_m;
  c.scene_max_N_per_m = scene.device.max_stiffness_N_per_m;
  c.device_max_N_per_m = device.max_stiffness_N_per_m;
  c.damping_Ns_per_m = device.damping_Ns_per_m;
  c.rate_hz = rate_hz;
  // K < 2 b / T with T = 1 / rate
  c.passivity_max_N_per_m = CouplingLimit::kPassivityShare * 2.0 * device.damping_Ns_per_m * rate_hz;
  const std::pair<double, const char*> limits[] = {{c.scene_N_per_m, "scene coupling_N_per_m"},
                                                   {c.scene_max_N_per_m, "scene device.max_stiffness_N_per_m"},
                                                   {c.device_max_N_per_m, "device max_stiffness_N_per_m"},
                                                   {c.passivity_max_N_per_m, "passivity 2b/T"}};
  c.stiffness_N_per_m = limits[0].first;
  c.bound = limits[0].second;
  for (const auto& [value, name] : limits)
    if (value < c.stiffness_N_per_m) {
      c.stiffness_N_per_m = value;
      c.bound = name;
    }
  return c;
}

ServoParams servo_params_for(const Scene& scene, const DeviceSpecs& device) {
  ServoParams sp;
  sp.mode = scene.mode;
  // the coupling never renders more stiffness than the device can display stably, by the scene's word, its own,
  // or the passivity bound at this rate
  sp.coupling_N_per_m = coupling_limit(scene, device).stiffness_N_per_m;
  sp.coupling_damping_Ns_per_m = scene.device.coupling_damping_Ns_per_m;
  sp.passivity = scene.device.passivity;
  sp.ramp_s = scene.device.ramp_s;
  sp.grab_radius_m = scene.grab_radius_m;
  sp.blade_length_m = scene.blade_length_m;
  sp.cut_resistance_Ns_per_m = scene.cut_resistance_Ns_per_m;
  sp.tool_radius_m = scene.device.sphere_tool ? scene.device.tool_radius_m : 0.0;
  sp.friction.static_coefficient = scene.static_friction;
  sp.friction.dynamic_coefficient = scene.dynamic_friction;
  sp.jump_limit_N_per_tick = scene.device.jump_limit_N_per_tick;
  sp.force_shading_deg = scene.device.force_shading_deg;
  // a grab is predicted between frames except on a symplectic lattice (ServoParams::predict_grab): explicit Euler's
  // substeps damp within the frame as the implicit steps do, and unpredicted its shipped pull (bunny_pull_explicit)
  // traded the pull frame by frame with the coupling: 757 steps over 0.1 N and 1.26 J given to the scripted hand
  sp.predict_grab = scene.lattice.integrator != IntegratorKind::kSymplecticEuler;
  // after breakaway the friction force comes down to the sliding level no faster than the jump limit
  if (sp.coupling_N_per_m > 0.0) sp.friction.trail_drop_m = sp.jump_limit_N_per_tick / sp.coupling_N_per_m;
  return sp;
}

}  // namespace palpate
