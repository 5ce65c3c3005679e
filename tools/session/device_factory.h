#pragma once
/// Device factory: builds the Device a recording runs against from the scene and the --device override,
/// and reports what the driver saw (link events, rejected input) after the run.

#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/result.h"
#include "core/scene.h"
#include "haptics/device.h"
#include "haptics/servo.h"

namespace palpate {

/// Creates the device named by `spec`: "scripted", "shm:NAME", "plugin:PATH.so", "replay:PATH" (a haptic.csv or
/// a recording folder), or empty for the scene's device.driver (+ device.link). Errors name the driver and the problem.
Result<std::unique_ptr<Device>> make_device(const Scene& scene, const std::string& spec, double rate_hz);

/// The driver of a spec (shm for "shm:x"; the scene's driver when spec is empty); nothing for an unknown driver
/// (make_device names it).
std::optional<DeviceDriver> device_driver(const Scene& scene, const std::string& spec);

/// Writes <out_dir>/device_events.csv (tick,t_s,event,silent_ms) via a temporary name when the driver keeps
/// link events, and prints one line per event to stderr unless quiet. Errors name the file.
Status write_device_events(const Device& device, const std::string& out_dir, bool quiet);

/// The config string handed to a plugin's open(): scene path, hand and keyframes as C99 hex floats.
std::string plugin_config(const Scene& scene);

/// The servo as a scene asks for it at rate_hz: the coupling capped at the stable stiffness of the scene's
/// device.max_stiffness_N_per_m and of the device itself (its specs, as shm and plugin drivers report them),
/// passivity, ramp, grab and blade settings, period 1 / rate_hz. Every driver of the pipeline (record,
/// benchmarks, tests) starts from this.
ServoParams servo_params_for(const Scene& scene, const DeviceSpecs& device, double rate_hz);

}  // namespace palpate
