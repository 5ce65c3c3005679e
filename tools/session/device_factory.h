#pragma once
/// Device factory: builds the Device a recording runs against from the scene and the --device override.

#include <memory>
#include <string>

#include "core/result.h"
#include "core/scene.h"
#include "haptics/device.h"

namespace palpate {

/// Creates the device named by `spec` ("scripted", or empty for the scene's device.driver).
/// Errors name the driver and the problem.
Result<std::unique_ptr<Device>> make_device(const Scene& scene, const std::string& spec, double rate_hz);

}  // namespace palpate
