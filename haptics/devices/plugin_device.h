#pragma once
/// PluginDevice: the `plugin` driver — a device implemented by a shared object with the small C ABI of
/// haptics/shim/palpate_plugin.h, loaded at run time (dlopen), so vendor SDK wrappers are built apart.

#include <memory>
#include <string>

#include "core/result.h"
#include "haptics/devices/device.h"
#include "haptics/shim/palpate_plugin.h"

namespace palpate {

/// A loaded plugin device. Not copyable; closes the device and unloads the object on destruction.
/// Thread: read()/write_force() on the servo thread (as allocation-free as the plugin is).
class PluginDevice final : public Device {
 public:
  /// Loads `path`, checks its ABI version and table size, opens it with `config`, reads and checks its specs;
  /// `limits` caps them. Errors name the file and the problem (dlopen message, missing entry, plugin message).
  static Result<std::unique_ptr<PluginDevice>> load(const std::string& path, const std::string& config,
                                                    const DeviceSpecs& limits);
  ~PluginDevice() override;
  PluginDevice(const PluginDevice&) = delete;
  PluginDevice& operator=(const PluginDevice&) = delete;

  const DeviceSpecs& specs() const noexcept override { return specs_; }
  /// The plugin's reading; false when it has none or it is not finite (counted).
  bool read(double t_s, DevicePose* out) noexcept override;
  /// Clamps to max_force_N (non-finite -> zero) and passes it on.
  void write_force(const Vec3& force_N) noexcept override;

  /// The plugin's name.
  const std::string& name() const noexcept { return name_; }
  /// Readings the plugin did not deliver or that were not finite.
  int64_t bad_readings() const noexcept { return bad_readings_; }
  /// Driver "plugin": its name and refused readings.
  nlohmann::json report() const override {
    return {{"driver", "plugin"}, {"name", name_}, {"bad_readings", bad_readings_}};
  }

 private:
  PluginDevice() = default;

  void* lib_ = nullptr;
  const palpate_plugin_api* api_ = nullptr;
  void* dev_ = nullptr;
  DeviceSpecs specs_;
  std::string name_;
  int64_t bad_readings_ = 0;
};

}  // namespace palpate
