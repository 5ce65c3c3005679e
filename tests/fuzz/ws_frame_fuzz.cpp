// libFuzzer target: the bytes a page sends over its WebSocket -> ws_parse_frame() frame after frame, as the server
// takes them (at most a few whole frames held), and each text payload -> parse_browser_message(). Whatever arrives:
// a frame never takes more than the buffer or less than its header, a payload within its limit, a refusal with a
// known close code and a reason, and a parsed pose or change of the controls only with its fields in range.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "runtime/live/browser_message.h"
#include "runtime/live/ws_frame.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  using namespace palpate;
  const WsLimits limits;
  std::string_view in(reinterpret_cast<const char*>(data), size);
  for (int frames = 0; frames < 64 && !in.empty(); ++frames) {
    const std::string_view buffer = in.substr(0, 4 * ws_max_frame_bytes(limits));
    const WsParse p = ws_parse_frame(buffer, limits);
    if (p.kind == WsParse::Kind::kIncomplete) {
      // an incomplete frame always leaves room to read the rest
      if (buffer.size() >= ws_max_frame_bytes(limits)) std::abort();
      break;
    }
    if (p.kind == WsParse::Kind::kError) {
      if (p.reason.empty()) std::abort();
      if (p.close_code != kWsCloseProtocol && p.close_code != kWsCloseUnsupported && p.close_code != kWsCloseBadData &&
          p.close_code != kWsCloseTooBig)
        std::abort();
      break;
    }
    if (p.consumed < 6 || p.consumed > buffer.size() || p.payload.size() > limits.max_payload_bytes) std::abort();
    if (p.opcode == WsOpcode::kText) {
      const BrowserMessage m = parse_browser_message(p.payload);
      if (m.kind == BrowserMessage::Kind::kError && m.reason.empty()) std::abort();
      if (m.kind == BrowserMessage::Kind::kPose &&
          (m.seq < 1 || !(std::fabs(m.x) <= 1.0) || !(std::fabs(m.y) <= 1.0) || !(std::fabs(m.depth) <= 1.0) ||
           m.buttons > 3))
        std::abort();
      // controls: a mode, and a stiffness and a radius within what the message may say (the scene bounds them after)
      if (m.kind == BrowserMessage::Kind::kControls &&
          (!(m.stiffness_scale >= 1e-3 && m.stiffness_scale <= 1e3) || !(m.tool_radius_m >= 1e-6 && m.tool_radius_m <= 1.0) ||
           (m.mode != InteractionMode::kTouch && m.mode != InteractionMode::kPull && m.mode != InteractionMode::kCut)))
        std::abort();
    }
    in.remove_prefix(p.consumed);
  }
  return 0;
}
