#pragma once
/// BrowserDevice: the `browser` driver — a page of the live view steers the tool with its pointer. Messages arrive
/// at the page's pace (about 60 a second, unevenly) through a BrowserLink; every servo tick the device moves a target
/// along a straight line from where it was to the newest message over the measured message interval (no steps),
/// and a hand model (the scene's mass-spring-damper hand, pushed back by the device force as a held handle is)
/// follows the target, so the 1 kHz force is smooth between messages. Watchdog: a page that closes, is refused or
/// falls silent for stall_s fades the force to zero over fade_s (DevicePose::force_scale), then gives no reading.
///
/// Input is relative, like a clutch: the first message of a page's control (its first ever, or a page taking over)
/// anchors the pointer where the tool is — the scene's start before any — and moves nothing; only later messages
/// that move the pointer or change the buttons engage the device, and only then does the force fade in. After the
/// force faded out (the page fell silent) the device engages again only on a message that moves from the page's last. So a page that connects, reloads or takes over mid-press pushes nothing until its user moves,
/// and a blade never sweeps from a default pose. A change of the controls (core/controls.h: the model starts again)
/// puts the tool back where it waited, fades the force out, and anchors the pointer afresh at the next message.

#include <cstdint>

#include "core/rates.h"
#include "core/scene.h"
#include "haptics/devices/browser_link.h"
#include "haptics/devices/device.h"

namespace palpate {

/// The plane the pointer moves the tool on: the view's centre and axes (world), and its half-sizes. Plain data.
struct BrowserView {
  Vec3 centre_m = Vec3::Zero();    ///< the point under the middle of the view at depth 0
  Vec3 right = Vec3::UnitX();      ///< unit, across the view
  Vec3 up = Vec3::UnitZ();         ///< unit, up the view
  Vec3 forward = Vec3::UnitY();    ///< unit, from the eye into the view
  double half_width_m = 0.05;      ///< x = +-1 this far from the centre
  double half_height_m = 0.05;     ///< y = +-1
  double half_depth_m = 0.05;      ///< depth = +-1
  Vec3 eye_m = Vec3(0.0, -0.2, 0.0);  ///< the camera's eye (for where the picture shows the tool)
  double tan_half_fov_y = 0.25;    ///< tan of half the camera's vertical field of view
  double aspect = 1.0;             ///< the picture's width / height
};

/// Watchdog and interpolation settings. Plain data.
struct BrowserParams {
  double stall_s = scene_defaults().device.browser_stall_ms * 1e-3;  ///< no message this long: the page has stalled
                                                                      ///< (device.browser_stall_ms)
  double fade_s = 0.1;             ///< the force fades from full to zero over this (and back in, at the same rate)
  double min_interval_s = 0.004;   ///< the interpolation spans the measured message interval, at least this
  double max_interval_s = 0.05;    ///< and at most this
  /// Watchdog time: from a page's last message (or its close) to zero force, at most.
  double watchdog_s() const { return stall_s + fade_s; }
};

/// The watchdog of a scene's browser device (device.browser_stall_ms).
inline BrowserParams browser_params(const Scene& scene) {
  BrowserParams p;
  p.stall_s = scene.device.browser_stall_ms * 1e-3;
  return p;
}

/// Counters of what the device saw. Plain data.
struct BrowserCounters {
  int64_t messages = 0;      ///< new messages used
  int64_t stalls = 0;        ///< times the page fell silent past stall_s
  int64_t releases = 0;      ///< times the controlling page went away
  int64_t silent_ticks = 0;  ///< ticks without a reading (no page, or faded out)
  double max_gap_ms = 0.0;   ///< longest interval between two messages
};

/// The browser driver. Not copyable. Thread: read()/write_force() on the servo thread (no allocation, lock, I/O);
/// set_view() before the servo starts; the rest after the run.
class BrowserDevice final : public Device {
 public:
  /// A monotonic clock in ns (injectable for tests).
  using ClockFn = int64_t (*)();
  /// link must outlive the device; rates (the run's) too. clock: null = monotonic_ns.
  BrowserDevice(const DeviceSpecs& specs, const HandSpec& hand, const BrowserParams& params, BrowserLink* link,
                const Rates& rates, ClockFn clock = nullptr);
  BrowserDevice(const DeviceSpecs&, const HandSpec&, const BrowserParams&, BrowserLink*, Rates&&, ClockFn = nullptr) = delete;

  /// Sets the plane the pointer moves on. Thread: before the servo starts.
  void set_view(const BrowserView& view) noexcept { view_ = view; }
  /// Where the tool waits before any page steers it (world); the view's centre unless set. Thread: before the servo.
  void set_start(const Vec3& start_m) noexcept {
    start_m_ = handle_m_ = target_m_ = from_m_ = to_m_ = start_m;
    started_ = true;
  }
  /// The plane the pointer moves on.
  const BrowserView& view() const noexcept { return view_; }
  /// The controls the run starts with (the scene's own, seq 0). Thread: before the servo starts.
  void set_controls(const Controls& c) noexcept { controls_ = c; }

  const DeviceSpecs& specs() const noexcept override { return specs_; }
  /// The hand model's handle after one servo period toward the interpolated target; false before any message and
  /// once the watchdog has faded the force out (force_scale carries the fade).
  bool read(double t_s, DevicePose* out) noexcept override;
  /// Takes the force (clamped to max_force_N) for the hand model and publishes it to the page.
  void write_force(const Vec3& force_N) noexcept override;

  /// The world point of a message (the view plane, no hand, no anchor). Thread: any.
  Vec3 world_of(const BrowserInput& in) const noexcept;
  /// Where the camera's picture shows a world point: x, y in -1..1 across it, z the distance along the view (m).
  Vec3 screen_of(const Vec3& p_m) const noexcept;
  /// Counters so far.
  const BrowserCounters& counters() const noexcept { return counters_; }
  /// The watchdog and interpolation settings.
  const BrowserParams& params() const noexcept { return params_; }
  /// Driver "browser": messages, stalls, releases, watchdog.
  nlohmann::json report() const override;

 private:
  DeviceSpecs specs_;
  HandSpec hand_;
  BrowserParams params_;
  BrowserLink* link_;
  const Rates& rates_;
  ClockFn clock_;
  BrowserView view_;
  BrowserCounters counters_;
  BrowserFeedback fb_;
  int64_t seq_ = 0;              // newest message used
  int64_t last_rx_ns_ = 0;       // its receipt
  double interval_s_ = 1.0 / 60.0;  // the message interval, smoothed
  Vec3 from_m_ = Vec3::Zero();   // the target's segment: from, to, start, length
  Vec3 to_m_ = Vec3::Zero();
  int64_t seg_start_ns_ = 0;
  double seg_s_ = 0.0;
  Vec3 target_m_ = Vec3::Zero();
  Vec3 handle_m_ = Vec3::Zero(); // hand model state
  Vec3 vel_m_per_s_ = Vec3::Zero();
  Vec3 force_N_ = Vec3::Zero();  // last force written
  uint32_t buttons_ = 0;
  Vec3 offset_m_ = Vec3::Zero(); // anchor: the tool's target is a message's world point plus this
  BrowserInput anchor_;          // the message the page must move from to engage (its control's first, or its last
                                 // before the force faded out)
  BrowserInput last_in_;         // the newest message used
  int64_t session_ = 0;          // the page control that message belongs to
  bool anchored_ = false;        // a page's control is anchored (false before any message)
  bool engaged_ = false;         // its pointer or buttons moved since: the force may flow
  bool started_ = false;         // set_start() placed the tool
  Vec3 start_m_ = Vec3::Zero();  // where it waits before a page steers (and after a change of the controls)
  Controls controls_;            // the controls handed to the servo
  bool reanchor_ = false;        // the controls changed: the next message anchors the pointer afresh
  bool at_start_ = false;        // and the hand is held where it waited until the page engages again
  double scale_ = 0.0;           // the watchdog's fade
  int64_t last_ns_ = 0;          // clock at the last read()
  bool stalled_ = false;
  bool was_live_ = false;
};

}  // namespace palpate
