#include "tools/session/device_factory.h"

#include "haptics/scripted_device.h"

namespace palpate {

Result<std::unique_ptr<Device>> make_device(const Scene& scene, const std::string& spec, double rate_hz) {
  const std::string driver = spec.empty() ? scene.device.driver : spec;
  DeviceSpecs specs;
  specs.max_force_N = scene.device.max_force_N;
  specs.workspace_half_m = scene.device.workspace_half_m;
  specs.rate_hz = rate_hz;
  if (driver == "scripted") {
    return std::unique_ptr<Device>(std::make_unique<ScriptedDevice>(specs, scene.hand, scene.trajectory));
  }
  return make_error("device '", driver, "': unknown driver (known: scripted)");
}

}  // namespace palpate
