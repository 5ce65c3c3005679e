#pragma once
/// DeviceServer: the loop of palpate-device — the emulated hand device (haptics/scripted_device) served through
/// the shared-memory shim at its own clock (absolute deadlines), with a watchdog on the sim's heartbeat that
/// ramps the force to zero when the sim goes silent, timing figures, an optional per-tick log and fault injection.

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "core/result.h"
#include "core/scene.h"
#include "haptics/servo/latency_histogram.h"

namespace palpate {

/// A bad pose to publish on purpose (tests of the sim's input checks).
struct InjectedFault {
  enum class Kind { kNonFinite, kOutside, kJump } kind = Kind::kNonFinite;
  double t_s = 0.0;  ///< trajectory time (from the first sim connection) to publish it at, for 5 ms
};

/// What to serve and how.
struct DeviceServerOptions {
  std::string name;                  ///< shim link name
  HandSpec hand;                     ///< hand model
  std::vector<Keyframe> trajectory;  ///< non-empty, increasing times
  double max_force_N = 3.3;          ///< device force limit
  double workspace_half_m = 0.5;     ///< device workspace
  double rate_hz = kDefaultServoRate_hz;  ///< device clock
  double duration_s = 0.0;           ///< stop after this long (0: until a signal)
  double sim_watchdog_ms = 10.0;     ///< sim silent this long -> release the force
  double release_ms = 100.0;         ///< force ramp to zero (and back in) time
  std::string log_path;              ///< per-tick CSV (empty: none)
  std::vector<InjectedFault> faults; ///< bad poses to publish
  bool quiet = false;                ///< no event lines
};

/// What a run measured.
struct DeviceServerReport {
  int64_t ticks = 0;                 ///< device ticks run
  LatencyHistogram wake_latency;     ///< actual - intended wake time
  LatencyHistogram round_trip;       ///< pose published -> its force seen by the device (at the next device tick)
  LatencyHistogram pose_to_force;    ///< pose published -> force written by the sim (both stamped on CLOCK_MONOTONIC)
  int64_t overruns = 0;              ///< periods skipped
  int64_t forces = 0;                ///< new force commands received
  int64_t rejected_forces = 0;       ///< non-finite force commands or ones past max_force_N (replaced by zero)
  int64_t sim_lost = 0;              ///< times the sim went silent
  int64_t sim_found = 0;             ///< times a sim's heartbeat started (or resumed)
  double max_force_applied_N = 0.0;  ///< largest force applied to the handle
};

/// Serves until `stop` is set (signal handler) or the duration ends. Errors: segment creation, log file.
Result<DeviceServerReport> run_device_server(const DeviceServerOptions& options, const std::atomic<bool>& stop);

/// Parses "nan@0.3", "outside@0.5", "jump@0.7" (comma-separated); errors name the item.
Result<std::vector<InjectedFault>> parse_faults(const std::string& text);

}  // namespace palpate
