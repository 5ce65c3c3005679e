#pragma once
/// ReplayDevice: the `replay` driver — plays back the device poses and buttons of a recording's haptic.csv,
/// so a session recorded with a device (or the emulator) re-runs headless; ticks the recording's servo rejected
/// are rejected again, so a lockstep replay reproduces the recording's state hash.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/result.h"
#include "haptics/device.h"

namespace palpate {

/// One recorded device reading.
struct ReplayRow {
  double t_s = 0.0;            ///< scene time of the tick
  Vec3 pos_m = Vec3::Zero();   ///< tool position (world)
  uint32_t buttons = 0;        ///< buttons
  bool rejected = false;       ///< the recording's servo rejected this tick's reading
};

/// Parses haptic.csv text (columns found by header name: t_s, tool_x_m, tool_y_m, tool_z_m, buttons, and
/// optionally rejected); errors name the file, the line and the column.
Result<std::vector<ReplayRow>> parse_haptic_csv(const std::string& text, const std::string& path);
/// Reads a haptic.csv file, or <folder>/haptic.csv when `path` is a recording folder; only a regular file of at
/// most kMaxReplayFileBytes (errors as read_input_file()).
Result<std::vector<ReplayRow>> load_haptic_csv(const std::string& path);

/// The replay driver. Copyable. Thread: servo (read/write_force).
class ReplayDevice final : public Device {
 public:
  /// rows: non-empty, times increasing (load_haptic_csv guarantees it).
  ReplayDevice(const DeviceSpecs& specs, std::vector<ReplayRow> rows);

  const DeviceSpecs& specs() const noexcept override { return specs_; }
  /// The last row at or before t_s (the first before it starts, the last after it ends); false on a row the
  /// recording rejected.
  bool read(double t_s, DevicePose* out) noexcept override;
  /// Forces are not played anywhere; the last one is kept for inspection.
  void write_force(const Vec3& force_N) noexcept override { force_N_ = force_N; }

  /// Rows loaded.
  std::size_t size() const noexcept { return rows_.size(); }
  /// Duration covered (s).
  double duration_s() const noexcept { return rows_.back().t_s - rows_.front().t_s; }
  /// Driver "replay": rows and their time span.
  nlohmann::json report() const override {
    return {{"driver", "replay"}, {"rows", rows_.size()}, {"duration_s", duration_s()}};
  }
  /// Last force written.
  const Vec3& last_force_N() const noexcept { return force_N_; }

 private:
  DeviceSpecs specs_;
  std::vector<ReplayRow> rows_;
  std::size_t cursor_ = 0;  // the row last returned: forward playback is O(1) per tick
  Vec3 force_N_ = Vec3::Zero();
};

}  // namespace palpate
