#pragma once
/// Device factory: builds the Device a recording runs against from the scene and the --device override,
/// and reports what the driver saw (link events, rejected input) after the run.

#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/result.h"
#include "core/scene.h"
#include "haptics/browser_link.h"
#include "haptics/device.h"
#include "haptics/servo.h"

namespace palpate {

/// Creates the device named by `spec`: "scripted", "shm:NAME", "plugin:PATH.so", "replay:PATH" (a haptic.csv or
/// a recording folder), "browser" (the live page, through `browser`, which must then be given and outlive the
/// device), or empty for the scene's device.driver (+ device.link). Errors name the driver and the problem.
/// The device reads scene.rates: the scene must outlive it.
Result<std::unique_ptr<Device>> make_device(const Scene& scene, const std::string& spec, BrowserLink* browser = nullptr);

/// The driver of a spec (shm for "shm:x"; the scene's driver when spec is empty); an unknown driver is an error
/// naming it.
Result<DeviceDriver> device_driver(const Scene& scene, const std::string& spec);

/// Writes <out_dir>/device_events.csv (tick,t_s,event,silent_ms) via a temporary name when the driver keeps
/// link events, and prints one line per event to stderr unless quiet. Errors name the file.
Status write_device_events(const Device& device, const std::string& out_dir, bool quiet);

/// The config string handed to a plugin's open(): scene path, hand and keyframes as C99 hex floats.
std::string plugin_config(const Scene& scene);

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
