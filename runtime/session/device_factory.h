#pragma once
/// Device factory: builds the Device a recording runs against from the scene and the --device override,
/// and reports what the driver saw (link events, rejected input) after the run.

#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/result.h"
#include "core/scene.h"
#include "haptics/devices/browser_link.h"
#include "haptics/devices/device.h"
#include "haptics/servo/servo.h"
#include "haptics/servo/servo_params.h"

namespace palpate {

/// What a device of `driver` can do in this scene: its force, stiffness and workspace from device.*, its damping the
/// hand's when the scene's hand holds it (scripted), else the device's.
DeviceSpecs device_specs_for(const Scene& scene, DeviceDriver driver);

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

}  // namespace palpate
