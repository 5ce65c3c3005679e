#pragma once
/// Device: the one interface every haptic driver implements (SI units, world frame after workspace mapping).

#include <cstdint>

#include <string>

#include <nlohmann/json.hpp>

#include "core/controls.h"
#include "core/rates.h"
#include "core/run_schedule.h"
#include "core/types.h"

namespace palpate {

/// What a device can do; fixed for its lifetime.
struct DeviceSpecs {
  double max_force_N = 3.3;               ///< force clamp
  double max_stiffness_N_per_m = 700.0;   ///< highest stable rendered stiffness
  double workspace_half_m = 0.5;          ///< poses outside this cube around the origin are rejected
  double rate_hz = kDefaultServoRate_hz;  ///< the device's own clock (shm, plugin; not the servo's rate, Scene::rates)
  double damping_Ns_per_m = 2.0;          ///< physical viscous damping at the handle (b of the passivity bound)
};

/// One reading of the device.
struct DevicePose {
  Vec3 pos_m = Vec3::Zero();          ///< handle position (world)
  Quat orientation = Quat::Identity();///< handle orientation (world)
  uint32_t buttons = 0;               ///< bit 0 = main button
  double force_scale = 1.0;           ///< the driver's own fade, 0..1 (a link's watchdog): the servo scales its force
  Controls controls{};                ///< what a person set (the browser page's controls; replayed from a log): the
                                      ///< servo acts on a larger seq, whether or not the reading itself is good
};

/// A haptic device. Thread: read() and write_force() are called by the servo thread only;
/// they never allocate, lock, log, throw or block.
class Device {
 public:
  virtual ~Device() = default;
  /// The device's limits.
  virtual const DeviceSpecs& specs() const noexcept = 0;
  /// Reads the pose at scene time t_s; false when no reading is available (the servo keeps the last good one).
  virtual bool read(double t_s, DevicePose* out) noexcept = 0;
  /// Commands a force (N) to be applied until the next call.
  virtual void write_force(const Vec3& force_N) noexcept = 0;

  /// What the driver reports after a run for summary.json: {"driver": name, its own figures}. Not for the servo
  /// thread (it allocates).
  virtual nlohmann::json report() const { return {{"driver", "custom"}}; }
  /// Link events (connected, disconnected, ...) for device_events.csv; null for a driver without a link.
  virtual const class DeviceEventLog* link_events() const noexcept { return nullptr; }
  /// The link's name for messages about its events (empty without a link).
  virtual std::string link_name() const { return {}; }
  /// A driver that plays a recorded run back: the order its ticks and frames met, which a session follows instead
  /// of its own clock (core/run_schedule.h); null for every other driver.
  virtual const RunSchedule* schedule() const noexcept { return nullptr; }
};

}  // namespace palpate
