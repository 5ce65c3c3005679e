#pragma once
/// BrowserLink: the lock-free channel between the live view's server thread (a page's pointer messages in, the
/// device's force out for display) and the servo thread's BrowserDevice. Two TripleBuffers and an atomic; neither
/// side ever waits for the other.

#include <atomic>
#include <cstdint>

#include "core/controls.h"
#include "core/triple_buffer.h"
#include "core/types.h"

namespace palpate {

/// One pointer message from the controlling page, in the view's normalised coordinates. Plain data.
struct BrowserInput {
  int64_t seq = 0;            ///< the page's message number (increasing; 0 = none yet)
  double x = 0.0;             ///< across the view, -1 (left edge) .. 1 (right edge)
  double y = 0.0;             ///< up the view, -1 (bottom) .. 1 (top)
  double depth = 0.0;         ///< along the view direction, -1 (toward the eye) .. 1 (away)
  uint32_t buttons = 0;       ///< bit 0 = main button (grab in pull, blade down in cut)
  int64_t received_ns = 0;    ///< monotonic time the server read it
  int64_t session = 0;        ///< which page's control this is (a new number each time control passes to a page):
                              ///< the device re-anchors on a new one, so a page taking over moves nothing
};

/// What the servo last did with the page's input, for the page and /stats.json. Plain data.
struct BrowserFeedback {
  Vec3 force_N = Vec3::Zero();   ///< force last written by the servo (N)
  Vec3 handle_m = Vec3::Zero();  ///< the hand model's handle (world)
  Vec3 target_m = Vec3::Zero();  ///< the interpolated target the hand follows (world)
  Vec3 force_view_N = Vec3::Zero();  ///< the force along the view's right, up and forward axes (N)
  Vec3 handle_view = Vec3::Zero();   ///< the handle in the view's normalised x, y, depth
  Vec3 handle_screen = Vec3::Zero(); ///< the handle as the camera sees it: x, y in -1..1 across the picture
                                     ///< (perspective), z its distance from the eye along the view (m)
  Vec3 view_half_mm = Vec3::Zero();  ///< the view plane's half width, half height and half depth (mm)
  bool engaged = false;          ///< the controlling page has moved since it took control (force may flow)
  double force_scale = 0.0;      ///< the watchdog's fade: 1 live, 0 silent
  int64_t seq = 0;               ///< newest input the servo has used
  int64_t input_to_force_ns = 0; ///< that input: server receipt to the first force computed from it
  int64_t ticks = 0;             ///< servo ticks so far
  Controls controls{};           ///< the controls the device last handed the servo
};

/// The channel. Not copyable. Thread: post/release/feedback on the server thread; take/publish on the servo thread.
class BrowserLink {
 public:
  BrowserLink() = default;
  BrowserLink(const BrowserLink&) = delete;
  BrowserLink& operator=(const BrowserLink&) = delete;

  /// Publishes the controlling page's newest message. Thread: server.
  void post(const BrowserInput& in) noexcept {
    input_.write_buffer() = in;
    input_.publish();
    live_.store(true, std::memory_order_release);
  }
  /// Publishes a change of the controls the server checked (core/scene_controls.h), seq larger than the last. Thread:
  /// server.
  void post_controls(const Controls& c) noexcept {
    controls_.write_buffer() = c;
    controls_.publish();
  }
  /// The controlling page is gone (closed, refused for garbage): the device fades its force out now. Thread: server.
  void release() noexcept { live_.store(false, std::memory_order_release); }
  /// The servo's latest feedback. Thread: server.
  const BrowserFeedback& feedback() noexcept { return feedback_.read(); }

  /// The newest message (seq 0 before any). Thread: servo.
  const BrowserInput& take() noexcept { return input_.read(); }
  /// The newest controls (seq 0 before any change). Thread: servo.
  const Controls& take_controls() noexcept { return controls_.read(); }
  /// Whether a page controls the device (false after release() until the next post()). Thread: any.
  bool live() const noexcept { return live_.load(std::memory_order_acquire); }
  /// Publishes the servo's feedback. Thread: servo.
  void publish(const BrowserFeedback& f) noexcept {
    feedback_.write_buffer() = f;
    feedback_.publish();
  }

 private:
  TripleBuffer<BrowserInput> input_;
  TripleBuffer<BrowserFeedback> feedback_;
  TripleBuffer<Controls> controls_;
  std::atomic<bool> live_{false};
};

}  // namespace palpate
