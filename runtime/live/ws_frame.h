#pragma once
/// WebSocket frames (RFC 6455 §5) as the live view takes them from a page: masked client frames, one frame per
/// message (no fragments), small payloads, ASCII text. Pure functions, no I/O (fuzzed by tests/fuzz/ws_frame_fuzz.cpp).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace palpate {

/// Frame opcodes (RFC 6455 §5.2).
enum class WsOpcode : uint8_t { kContinuation = 0, kText = 1, kBinary = 2, kClose = 8, kPing = 9, kPong = 10 };

/// Close codes the server sends (RFC 6455 §7.4.1).
inline constexpr uint16_t kWsCloseNormal = 1000;
inline constexpr uint16_t kWsCloseProtocol = 1002;
inline constexpr uint16_t kWsCloseUnsupported = 1003;
inline constexpr uint16_t kWsCloseBadData = 1007;
inline constexpr uint16_t kWsClosePolicy = 1008;
inline constexpr uint16_t kWsCloseTooBig = 1009;

/// The bounds a client frame must keep. Plain data.
struct WsLimits {
  std::size_t max_payload_bytes = 256;  ///< text or binary payload; control frames are held to 125 by the RFC
};

/// The largest frame a client may send under `limits`: a 14-byte header (8-byte length, mask) and the payload.
inline std::size_t ws_max_frame_bytes(const WsLimits& limits) { return 14 + limits.max_payload_bytes; }

/// What parsing the front of a buffer gave. Plain data.
struct WsParse {
  enum class Kind { kIncomplete, kFrame, kError };
  Kind kind = Kind::kIncomplete;
  std::size_t consumed = 0;               ///< kFrame: bytes of the buffer the frame took
  WsOpcode opcode = WsOpcode::kText;      ///< kFrame
  std::string payload;                    ///< kFrame: unmasked
  uint16_t close_code = 0;                ///< kError: the code to close with
  std::string reason;                     ///< kError: what was wrong (for the close frame and the log)
};

/// Parses the first frame in `buffer`. kIncomplete while more bytes are needed and nothing seen so far breaks a
/// rule; kError as soon as one is broken: reserved bits or an unknown opcode, an unmasked frame, a fragment, a control
/// frame over 125 bytes, a payload over the limit, a length not in its shortest form, text that is not printable
/// ASCII, a close payload of one byte.
WsParse ws_parse_frame(std::string_view buffer, const WsLimits& limits);

/// A server frame (unmasked, final) carrying `payload` (at most 65535 bytes; longer is cut there).
std::string ws_encode_frame(WsOpcode opcode, std::string_view payload);

/// A close frame's payload: the code (big-endian) and a reason cut to fit in 123 bytes.
std::string ws_close_payload(uint16_t code, std::string_view reason);

}  // namespace palpate
