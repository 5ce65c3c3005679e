#pragma once
/// ReplayDevice: the `replay` driver — plays back the device poses and buttons of a recording's haptic.csv,
/// so a session recorded with a device (or the emulator) re-runs headless; ticks the recording's servo rejected
/// are rejected again, so a lockstep replay reproduces the recording's state hash. A log that says which frame took
/// each tick and which frame's patch it felt (`frame`, `model_frame`) also gives the run's schedule
/// (core/run_schedule.h): a session follows it, so a realtime run replays as it ran.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/result.h"
#include "core/run_schedule.h"
#include "haptics/devices/device.h"

namespace palpate {

/// One recorded device reading.
struct ReplayRow {
  double t_s = 0.0;            ///< scene time of the tick
  Vec3 pos_m = Vec3::Zero();   ///< tool position (world)
  uint32_t buttons = 0;        ///< buttons
  bool rejected = false;       ///< the recording's servo rejected this tick's reading
  double force_scale = 1.0;    ///< the driver's fade the recording's force was scaled by (a link's watchdog)
  bool scheduled = false;      ///< the log has the columns below (tick, frame, model_frame)
  int64_t tick = -1;           ///< servo tick index
  int64_t frame = -1;          ///< the sim frame that took the tick's sample (-1: after the last frame)
  int64_t model_frame = -1;    ///< the sim frame whose patch the tick felt (-1: none yet)
  Controls controls{};         ///< the controls the recording's servo ran the tick under (columns controls, mode,
                               ///< stiffness_scale, tool_radius_m, resets; seq 0 without them)
  int line = 0;                ///< the row's line in the file (for messages)
};

/// Parses haptic.csv text (columns found by header name: t_s, tool_x_m, tool_y_m, tool_z_m, buttons, and
/// optionally rejected, and tick, frame and model_frame together, and controls, mode, stiffness_scale, tool_radius_m
/// and resets together); errors name the file, the line and the column,
/// or the ticks where the schedule contradicts itself.
Result<std::vector<ReplayRow>> parse_haptic_csv(const std::string& text, const std::string& path);
/// Reads a haptic.csv file, or <folder>/haptic.csv when `path` is a recording folder; only a regular file of at
/// most kMaxReplayFileBytes (errors as read_input_file()).
Result<std::vector<ReplayRow>> load_haptic_csv(const std::string& path);

/// The frames a realtime recording skipped (summary.json's sim.skipped_frames) for a replay of `path` (a recording
/// folder, or its haptic.csv: the summary beside it); empty when there is no summary or it says none.
std::vector<int64_t> read_skipped_frames(const std::string& path);

/// The order of ticks and frames the rows record (core/run_schedule.h), without the frames the recording skipped;
/// nullopt when the log has no such columns; an error naming `path` when they contradict each other or `skipped`.
Result<std::optional<RunSchedule>> replay_schedule(const std::vector<ReplayRow>& rows, const std::vector<int64_t>& skipped,
                                                   const std::string& path);

/// The replay driver. Copyable. Thread: servo (read/write_force).
class ReplayDevice final : public Device {
 public:
  /// rows: non-empty, times increasing (load_haptic_csv guarantees it). schedule: the recording's order of ticks and
  /// frames for a session to follow (replay_schedule()); none: the rows are played by time.
  ReplayDevice(const DeviceSpecs& specs, std::vector<ReplayRow> rows, std::optional<RunSchedule> schedule = std::nullopt);

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
  /// The recorded run's ticks and frames in the order they met, when the log has them (and they are followed).
  const RunSchedule* schedule() const noexcept override { return schedule_ ? &*schedule_ : nullptr; }
  /// Last force written.
  const Vec3& last_force_N() const noexcept { return force_N_; }

 private:
  DeviceSpecs specs_;
  std::vector<ReplayRow> rows_;
  std::optional<RunSchedule> schedule_;
  std::size_t cursor_ = 0;  // the row last returned: forward playback is O(1) per tick
  Vec3 force_N_ = Vec3::Zero();
};

}  // namespace palpate
