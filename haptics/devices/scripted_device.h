#pragma once
/// ScriptedDevice: keyframes drive a hand model (mass, damping, stiffness toward the target) holding the handle,
/// so the commanded force pushes the handle back — a closed loop, as with a person.

#include <vector>

#include "core/scene.h"
#include "haptics/devices/device.h"

namespace palpate {

/// Emulated device + hand. Copyable. Thread: servo (read/write_force).
class ScriptedDevice final : public Device {
 public:
  /// Keyframes must be non-empty and increasing in time (Scene guarantees it).
  ScriptedDevice(const DeviceSpecs& specs, const HandSpec& hand, std::vector<Keyframe> keys);

  const DeviceSpecs& specs() const noexcept override { return specs_; }
  /// Integrates the hand from the previous call's time to t_s (0.1 ms substeps) and reports the handle.
  bool read(double t_s, DevicePose* out) noexcept override;
  void write_force(const Vec3& force_N) noexcept override { force_N_ = force_N; }
  /// Driver "scripted".
  nlohmann::json report() const override { return {{"driver", "scripted"}}; }

  /// Keyframe target position and button at time t_s (linear in position, button held until the next key).
  void target(double t_s, Vec3* pos_m, bool* button) const noexcept;
  /// Keyframe tool orientation at time t_s (slerp between keys; the hand holds it exactly).
  Quat orientation_at(double t_s) const noexcept;
  /// Handle velocity (m/s).
  const Vec3& velocity() const noexcept { return vel_m_per_s_; }

 private:
  DeviceSpecs specs_;
  HandSpec hand_;
  std::vector<Keyframe> keys_;
  Vec3 pos_m_ = Vec3::Zero();
  Vec3 vel_m_per_s_ = Vec3::Zero();
  Vec3 force_N_ = Vec3::Zero();
  double t_s_ = 0.0;
};

}  // namespace palpate
