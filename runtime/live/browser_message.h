#pragma once
/// The messages a live page sends over its WebSocket (ASCII text, one per frame), parsed strictly: anything else is
/// garbage and closes the socket. Pure functions, no I/O (fuzzed by tests/fuzz/ws_frame_fuzz.cpp).
///
///   p SEQ X Y DEPTH BUTTONS   the pointer: SEQ a positive integer, X Y DEPTH in -1..1 (the view plane and depth),
///                             BUTTONS 0..3 (bit 0 the main button)
///   l FORCE_MS FRAME_MS       latencies the page measured: input event to the force computed from it coming back,
///                             and to the first frame drawn after it (0..60000 ms each; -1 = not measured yet)
///   k                         the page is still open (it sends poses only while its user steers): keeps the
///                             socket, never control
///   c MODE STIFFNESS RADIUS_MM the page's controls: MODE touch, pull or cut, STIFFNESS the material's stiffness as a
///                             factor of the scene's (0.001..1000), RADIUS_MM the tool's radius (0.001..1000 mm); the
///                             server checks them against the scene's ranges (core/scene_controls.h)
///   r                         reset: the model starts again from rest
///   a SEQ                     the page has heard the controls numbered SEQ (its poses after this are made from
///                             where the tool went)

#include <cstdint>
#include <string>
#include <string_view>

#include "core/scene_enums.h"

namespace palpate {

/// A parsed page message. Plain data.
struct BrowserMessage {
  enum class Kind { kPose, kLatency, kAlive, kControls, kReset, kAck, kError };
  Kind kind = Kind::kError;
  int64_t seq = 0;             ///< kPose; kAck: the controls' number
  double x = 0.0, y = 0.0, depth = 0.0;  ///< kPose, each -1..1
  uint32_t buttons = 0;        ///< kPose
  double force_ms = -1.0;      ///< kLatency
  double frame_ms = -1.0;      ///< kLatency
  InteractionMode mode = InteractionMode::kTouch;  ///< kControls
  double stiffness_scale = 1.0;  ///< kControls
  double tool_radius_m = 0.0;    ///< kControls
  std::string reason;          ///< kError: what was wrong, quoting the field
};

/// Parses one message (see the file comment); errors name the field and the value.
BrowserMessage parse_browser_message(std::string_view text);

}  // namespace palpate
