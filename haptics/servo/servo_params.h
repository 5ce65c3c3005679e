#pragma once
/// The servo's parameters as a scene asks for them on a device: ServoParams takes its defaults from the scene's
/// (scene_defaults()), and servo_params_for() is the one place a scene's keys become the servo's. Every driver of the
/// pipeline (record, benchmarks, tests) starts from it.

#include "core/scene.h"
#include "haptics/devices/device.h"
#include "haptics/servo/servo.h"

namespace palpate {

/// The coupling stiffness a servo at the scene's servo rate may render, and which limit set it.
///
/// Colgate & Brown (1994): a virtual wall of stiffness K sampled every T seconds with a zero-order hold on a
/// device whose own viscous damping is b is passive when b > K T / 2, i.e. K < 2 b / T (the hold returns energy
/// like a negative damping of K T / 2; the device's damping must absorb it). The bound grows with the rate:
/// at 10 kHz ten times the stiffness of 1 kHz is passive. The coupling is the smallest of the scene's
/// coupling_N_per_m, the scene's device.max_stiffness_N_per_m, the device's own max_stiffness_N_per_m (its
/// specs) and kPassivityShare * 2 b / T; kPassivityShare keeps part of b as real damping (b - K T / 2 >= b / 2)
/// instead of sitting on the edge of stability.
struct CouplingLimit {
  static constexpr double kPassivityShare = 0.5;
  double stiffness_N_per_m = 0.0;       ///< the coupling used
  double scene_N_per_m = 0.0;           ///< device.coupling_N_per_m, what the scene asks for
  double scene_max_N_per_m = 0.0;       ///< device.max_stiffness_N_per_m
  double device_max_N_per_m = 0.0;      ///< the device's specs().max_stiffness_N_per_m
  double passivity_max_N_per_m = 0.0;   ///< kPassivityShare * 2 b / T
  double damping_Ns_per_m = 0.0;        ///< b, the device's specs().damping_Ns_per_m
  double rate_hz = 0.0;                 ///< 1 / T
  /// Which limit set the stiffness: "scene coupling_N_per_m", "scene device.max_stiffness_N_per_m",
  /// "device max_stiffness_N_per_m" or "passivity 2b/T" (the first of them in that order on a tie).
  const char* bound = "";
};

/// The coupling limit of a scene on a device at scene.rates.servo_hz (see CouplingLimit).
CouplingLimit coupling_limit(const Scene& scene, const DeviceSpecs& device);

/// The servo as a scene asks for it: the coupling capped by coupling_limit() (the scene's and the device's
/// stiffness limits and the passivity bound at the scene's servo rate), passivity, ramp, grab and blade settings.
/// Every driver of the pipeline (record, benchmarks, tests) starts from this.
ServoParams servo_params_for(const Scene& scene, const DeviceSpecs& device);

}  // namespace palpate
