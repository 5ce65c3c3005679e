#pragma once
/// ShmDevice: the `shm` driver — a device served by another process through the shared-memory shim
/// (haptics/shim/palpate_shim.h). Everything read from the peer is checked; a watchdog on the peer's heartbeat
/// zeroes the force at once when it goes silent (the servo ramps it back in when readings return).

#include <memory>
#include <string>

#include "core/rates.h"
#include "core/result.h"
#include "haptics/devices/device.h"
#include "haptics/devices/device_link.h"
#include "haptics/devices/shm_segment.h"

namespace palpate {

/// Link settings; validated by connect().
struct ShmParams {
  std::string name;                   ///< link name ("/palpate-NAME")
  double watchdog_s = 0.005;          ///< peer silent this long -> disconnected
  double max_speed_m_per_s = 10.0;    ///< faster pose changes are rejected as impossible
  double connect_timeout_s = 5.0;     ///< how long connect() waits for the device to publish the segment
};

/// Counters of what the link saw. Plain data.
struct ShmCounters {
  int64_t poses = 0;            ///< new poses accepted
  int64_t rejected_nonfinite = 0;///< poses with NaN/Inf
  int64_t rejected_outside = 0; ///< poses outside the workspace
  int64_t rejected_speed = 0;   ///< poses implying an impossible velocity
  int64_t torn_reads = 0;       ///< ticks the pose record was being rewritten throughout the read (no reading)
  int64_t stale_ticks = 0;      ///< ticks without a new pose for longer than the watchdog (no reading)
  int64_t disconnected_ticks = 0;///< ticks spent disconnected
  int64_t forces_sent = 0;      ///< force commands written
};

/// The shm driver. Not copyable. Thread: read()/write_force() on the servo thread (no allocation, lock,
/// syscall other than clock_gettime, or I/O); the accessors after the run.
class ShmDevice final : public Device {
 public:
  /// Connects to the device serving params.name; errors name the link and the problem (absent, foreign owner,
  /// loose mode, size or version mismatch, bad specs). `limits` caps the device's own specs (scene's max force).
  /// rates: the run's (Scene::rates: tick numbers of events, the speed check's period); must outlive the device.
  static Result<std::unique_ptr<ShmDevice>> connect(const ShmParams& params, const DeviceSpecs& limits,
                                                    const Rates& rates);
  static Result<std::unique_ptr<ShmDevice>> connect(const ShmParams&, const DeviceSpecs&, Rates&&) = delete;

  /// Removes the link name when the device is gone (crashed or stopped), so no segment is left behind.
  ~ShmDevice() override;
  ShmDevice(const ShmDevice&) = delete;
  ShmDevice& operator=(const ShmDevice&) = delete;

  const DeviceSpecs& specs() const noexcept override { return specs_; }
  /// Latest checked pose; false while disconnected, when this tick's new pose was rejected, when the record read
  /// torn, or when no new pose came for longer than the watchdog (a frozen hand is a missing reading, so the
  /// servo zeroes the force and ramps it back in).
  bool read(double t_s, DevicePose* out) noexcept override;
  /// Sends the force (zero while disconnected), clamped to max_force_N.
  void write_force(const Vec3& force_N) noexcept override;

  /// True while the peer's heartbeat is alive.
  bool connected() const noexcept { return connected_; }
  /// Link events (connected, disconnected, reconnected, peer_restarted) with their servo ticks.
  const DeviceEventLog& events() const noexcept { return events_; }
  /// Counters so far.
  const ShmCounters& counters() const noexcept { return counters_; }
  /// The link settings.
  const ShmParams& params() const noexcept { return params_; }
  /// Force (N) last written to the peer, after the link check and clamp.
  const Vec3& last_force_sent_N() const noexcept { return sent_N_; }
  /// Driver "shm": link, connection at the end, watchdog, events, pose and rejection counters.
  nlohmann::json report() const override;
  /// The link's events.
  const DeviceEventLog* link_events() const noexcept override { return &events_; }
  /// The link name.
  std::string link_name() const override { return params_.name; }

 private:
  ShmDevice(ShmSegment seg, const ShmParams& params, const DeviceSpecs& specs, const Rates& rates);
  bool accept(const palpate_shim_pose& p, int64_t now_ns) noexcept;

  ShmSegment seg_;
  ShmParams params_;
  const Rates& rates_;
  DeviceSpecs specs_;
  PeerWatchdog watchdog_;
  DeviceEventLog events_;
  ShmCounters counters_;
  DevicePose good_;              // last accepted pose
  static constexpr int kReanchorRejects = 20;  // speed rejections in a row before the new place is accepted
  int speed_rejects_in_row_ = 0;               // consecutive poses refused as too fast
  bool have_good_ = false;
  int64_t good_ns_ = 0;          // when it was accepted (our clock)
  uint64_t last_seq_ = 0;        // seq of the last pose looked at
  int64_t new_pose_ns_ = 0;      // when a pose with a new seq was last read (our clock); 0 = none yet
  int64_t last_pose_time_ns_ = 0;
  uint64_t epoch_ = 0;
  bool connected_ = false;
  bool ever_connected_ = false;
  int64_t now_ns_ = 0;           // clock at this tick's read()
  uint64_t force_seq_ = 0;
  Vec3 sent_N_ = Vec3::Zero();
};

}  // namespace palpate
