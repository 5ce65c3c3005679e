#include "runtime/live/ws_frame.h"

#include <algorithm>

namespace palpate {
namespace {

WsParse error(uint16_t code, std::string reason) {
  WsParse p;
  p.kind = WsParse::Kind::kError;
  p.close_code = code;
  p.reason = std::move(reason);
  return p;
}

bool known(uint8_t op) { return op <= 2 || (op >= 8 && op <= 10); }

}  // namespace

WsParse ws_parse_frame(std::string_view buffer, const WsLimits& limits) {
  const auto* b = reinterpret_cast<const uint8_t*>(buffer.data());
  const std::size_t n = buffer.size();
  if (n < 2) return {};
  const bool fin = (b[0] & 0x80) != 0;
  const uint8_t op = b[0] & 0x0F;
  // every rule the first two bytes can break is judged before anything else arrives
  if (b[0] & 0x70) return error(kWsCloseProtocol, "reserved bits set (no extension was agreed)");
  if (!known(op)) return error(kWsCloseProtocol, "unknown opcode " + std::to_string(op));
  if (!(b[1] & 0x80)) return error(kWsCloseProtocol, "client frame not masked");
  const bool control = op >= 8;
  if (!fin || op == 0) return error(kWsCloseUnsupported, "fragmented message (one frame per message here)");
  const uint8_t len7 = b[1] & 0x7F;
  if (control && len7 > 125) return error(kWsCloseProtocol, "control frame over 125 bytes");
  std::size_t header = 2;
  uint64_t len = len7;
  if (len7 == 126) {
    header = 4;
    if (n < header) return {};
    len = (uint64_t{b[2]} << 8) | b[3];
    if (len < 126) return error(kWsCloseProtocol, "length not in its shortest form");
  } else if (len7 == 127) {
    header = 10;
    if (n < header) return {};
    len = 0;
    for (int k = 0; k < 8; ++k) len = (len << 8) | b[2 + k];
    if (len >> 63) return error(kWsCloseProtocol, "length with its top bit set");
    if (len <= 0xFFFF) return error(kWsCloseProtocol, "length not in its shortest form");
  }
  if (!control && len > limits.max_payload_bytes)
    return error(kWsCloseTooBig, "message of " + std::to_string(len) + " bytes over the limit of " +
                                     std::to_string(limits.max_payload_bytes));
  if (op == 8 && len == 1) return error(kWsCloseProtocol, "close frame with a one-byte payload");
  const std::size_t mask_at = header;
  header += 4;
  if (n < header + len) return {};
  WsParse p;
  p.kind = WsParse::Kind::kFrame;
  p.consumed = header + static_cast<std::size_t>(len);
  p.opcode = static_cast<WsOpcode>(op);
  p.payload.resize(static_cast<std::size_t>(len));
  for (std::size_t i = 0; i < len; ++i) p.payload[i] = static_cast<char>(b[header + i] ^ b[mask_at + (i & 3)]);
  if (op == 1)
    for (const char c : p.payload)
      if (static_cast<uint8_t>(c) < 0x20 || static_cast<uint8_t>(c) > 0x7E)
        return error(kWsCloseBadData, "text that is not printable ASCII");
  return p;
}

std::string ws_encode_frame(WsOpcode opcode, std::string_view payload) {
  payload = payload.substr(0, 0xFFFF);
  std::string out;
  out.reserve(payload.size() + 4);
  out += static_cast<char>(0x80 | static_cast<uint8_t>(opcode));
  if (payload.size() < 126) {
    out += static_cast<char>(payload.size());
  } else {
    out += static_cast<char>(126);
    out += static_cast<char>(payload.size() >> 8);
    out += static_cast<char>(payload.size() & 0xFF);
  }
  out.append(payload);
  return out;
}

std::string ws_close_payload(uint16_t code, std::string_view reason) {
  std::string out;
  out += static_cast<char>(code >> 8);
  out += static_cast<char>(code & 0xFF);
  out.append(reason.substr(0, 123));
  return out;
}

}  // namespace palpate
