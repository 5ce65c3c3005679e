#pragma once
/// Link health for devices behind a process boundary: a counter-based watchdog on the peer's heartbeat,
/// a linear force ramp, and a fixed-capacity event log (connected / disconnected / reconnected / restarted).

#include <algorithm>
#include <array>
#include <cstdint>

namespace palpate {

/// What happened to a device link.
enum class DeviceEventKind : uint8_t { kConnected, kDisconnected, kReconnected, kPeerRestarted };

/// Name of an event kind as written in logs and summaries ("disconnected", ...).
inline const char* device_event_name(DeviceEventKind k) noexcept {
  switch (k) {
    case DeviceEventKind::kConnected: return "connected";
    case DeviceEventKind::kDisconnected: return "disconnected";
    case DeviceEventKind::kReconnected: return "reconnected";
    case DeviceEventKind::kPeerRestarted: return "peer_restarted";
  }
  return "?";
}

/// One link event, stamped with the servo tick it was noticed in.
struct DeviceEvent {
  int64_t tick = 0;               ///< servo tick (t_s * rate)
  double t_s = 0.0;               ///< scene time
  DeviceEventKind kind = DeviceEventKind::kConnected;
  double silent_ms = 0.0;         ///< how long the peer had been silent (disconnected / reconnected)
};

/// Events kept without allocating; later ones are counted as lost. Thread: one writer; read after it stops.
class DeviceEventLog {
 public:
  static constexpr int kCapacity = 256;  ///< events kept
  /// Appends an event (or counts it lost when full).
  void push(const DeviceEvent& e) noexcept {
    if (count_ < kCapacity) events_[static_cast<std::size_t>(count_++)] = e;
    else ++lost_;
  }
  /// Events kept.
  int count() const noexcept { return count_; }
  /// Event i (0 <= i < count()).
  const DeviceEvent& at(int i) const noexcept { return events_[static_cast<std::size_t>(i)]; }
  /// Events that did not fit.
  int64_t lost() const noexcept { return lost_; }

 private:
  std::array<DeviceEvent, kCapacity> events_{};
  int count_ = 0;
  int64_t lost_ = 0;
};

/// Declares the peer silent when its heartbeat counter has not changed for `timeout_ns` of our own clock.
/// The first value seen is a baseline: a peer counts as alive only once its counter has moved (a segment left
/// by a dead peer never looks alive). Copyable. Thread: the one that polls it.
class PeerWatchdog {
 public:
  /// timeout_ns > 0.
  explicit PeerWatchdog(int64_t timeout_ns = 5'000'000) noexcept : timeout_ns_(timeout_ns) {}
  /// Feeds the peer's counter as read at now_ns; returns true while the peer is alive.
  bool update(uint64_t count, int64_t now_ns) noexcept {
    if (!seen_) {
      seen_ = true;
      count_ = count;
      last_change_ns_ = now_ns;
      return false;
    }
    if (count != count_) {
      count_ = count;
      last_change_ns_ = now_ns;
      moved_ = true;
    }
    return moved_ && now_ns - last_change_ns_ <= timeout_ns_;
  }
  /// Time since the counter last changed (ns), as of now_ns.
  int64_t silent_ns(int64_t now_ns) const noexcept { return seen_ ? now_ns - last_change_ns_ : 0; }
  /// The watchdog time (ns).
  int64_t timeout_ns() const noexcept { return timeout_ns_; }

 private:
  int64_t timeout_ns_;
  uint64_t count_ = 0;
  int64_t last_change_ns_ = 0;
  bool seen_ = false;
  bool moved_ = false;
};

/// A gain in [0, 1] moving linearly toward a target at 1 / ramp_ns per ns (ramp_ns = 0: jumps). Copyable.
class ForceRamp {
 public:
  /// ramp_ns >= 0 is the time for a full 0 -> 1 (or 1 -> 0) sweep.
  explicit ForceRamp(int64_t ramp_ns = 200'000'000) noexcept : ramp_ns_(ramp_ns) {}
  /// Moves toward target (0 or 1) for the time since the last call and returns the gain.
  double update(double target, int64_t now_ns) noexcept {
    const int64_t dt_ns = started_ ? std::max<int64_t>(0, now_ns - last_ns_) : 0;
    started_ = true;
    last_ns_ = now_ns;
    if (ramp_ns_ <= 0) return gain_ = target;
    const double step = static_cast<double>(dt_ns) / static_cast<double>(ramp_ns_);
    gain_ = target > gain_ ? std::min(target, gain_ + step) : std::max(target, gain_ - step);
    return gain_;
  }
  /// Sets the gain at once as of now_ns (e.g. 0 when the link drops: force goes to zero immediately).
  void reset(double gain, int64_t now_ns) noexcept {
    gain_ = gain;
    last_ns_ = now_ns;
    started_ = true;
  }
  /// The current gain.
  double gain() const noexcept { return gain_; }

 private:
  int64_t ramp_ns_;
  double gain_ = 0.0;
  int64_t last_ns_ = 0;
  bool started_ = false;
};

}  // namespace palpate
