#include "runtime/live/browser_message.h"

#include <charconv>
#include <cmath>
#include <vector>

namespace palpate {
namespace {

BrowserMessage fail(std::string reason) {
  BrowserMessage m;
  m.reason = std::move(reason);
  return m;
}

// the space-separated fields of `text` (at most 8; more is an error the caller sees as a wrong count)
std::vector<std::string_view> fields(std::string_view text) {
  // a trailing or doubled space makes an empty field, which no message accepts
  std::vector<std::string_view> out;
  while (out.size() <= 8) {
    const auto sp = text.find(' ');
    out.push_back(text.substr(0, sp));
    if (sp == std::string_view::npos) break;
    text.remove_prefix(sp + 1);
  }
  return out;
}

bool number(std::string_view s, double lo, double hi, double* out) {
  if (s.empty() || s.size() > 24) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(*out) && *out >= lo && *out <= hi;
}

bool integer(std::string_view s, int64_t lo, int64_t hi, int64_t* out) {
  if (s.empty() || s.size() > 18) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && *out >= lo && *out <= hi;
}

// "<what> '<value>' <expected>" (built by appending: GCC 12 warns falsely on chains of operator+ here)
BrowserMessage bad(const char* what, std::string_view value, const char* expected) {
  std::string r(what);
  r.append(" '").append(value.substr(0, 24)).append("' ").append(expected);
  return fail(std::move(r));
}

}  // namespace

BrowserMessage parse_browser_message(std::string_view text) {
  const auto f = fields(text);
  if (f.empty() || f[0].empty()) return fail("empty message");
  if (f[0] == "p") {
    if (f.size() != 6) return fail("pose: 5 fields expected (SEQ X Y DEPTH BUTTONS), got " + std::to_string(f.size() - 1));
    BrowserMessage m;
    int64_t buttons = 0;
    if (!integer(f[1], 1, INT64_C(1) << 52, &m.seq)) return bad("pose: SEQ", f[1], "is not a positive integer");
    if (!number(f[2], -1.0, 1.0, &m.x)) return bad("pose: X", f[2], "is not a number in -1..1");
    if (!number(f[3], -1.0, 1.0, &m.y)) return bad("pose: Y", f[3], "is not a number in -1..1");
    if (!number(f[4], -1.0, 1.0, &m.depth)) return bad("pose: DEPTH", f[4], "is not a number in -1..1");
    if (!integer(f[5], 0, 3, &buttons)) return bad("pose: BUTTONS", f[5], "is not 0..3");
    m.buttons = static_cast<uint32_t>(buttons);
    m.kind = BrowserMessage::Kind::kPose;
    return m;
  }
  if (f[0] == "l") {
    if (f.size() != 3) return fail("latency: 2 fields expected (FORCE_MS FRAME_MS), got " + std::to_string(f.size() - 1));
    BrowserMessage m;
    if (!number(f[1], -1.0, 60000.0, &m.force_ms)) return bad("latency: FORCE_MS", f[1], "is not -1..60000");
    if (!number(f[2], -1.0, 60000.0, &m.frame_ms)) return bad("latency: FRAME_MS", f[2], "is not -1..60000");
    m.kind = BrowserMessage::Kind::kLatency;
    return m;
  }
  if (f[0] == "k") {
    if (f.size() != 1) return fail("alive: no fields expected, got " + std::to_string(f.size() - 1));
    BrowserMessage m;
    m.kind = BrowserMessage::Kind::kAlive;
    return m;
  }
  if (f[0] == "c") {
    if (f.size() != 4)
      return fail("controls: 3 fields expected (MODE STIFFNESS RADIUS_MM), got " + std::to_string(f.size() - 1));
    BrowserMessage m;
    const auto mode = from_name<InteractionMode>(f[1]);
    if (!mode) return bad("controls: MODE", f[1], "is not touch, pull or cut");
    m.mode = *mode;
    double radius_mm = 0.0;
    if (!number(f[2], 1e-3, 1e3, &m.stiffness_scale)) return bad("controls: STIFFNESS", f[2], "is not a number in 0.001..1000");
    if (!number(f[3], 1e-3, 1e3, &radius_mm)) return bad("controls: RADIUS_MM", f[3], "is not a number in 0.001..1000");
    m.tool_radius_m = radius_mm * 1e-3;
    m.kind = BrowserMessage::Kind::kControls;
    return m;
  }
  if (f[0] == "r") {
    if (f.size() != 1) return fail("reset: no fields expected, got " + std::to_string(f.size() - 1));
    BrowserMessage m;
    m.kind = BrowserMessage::Kind::kReset;
    return m;
  }
  if (f[0] == "a") {
    if (f.size() != 2) return fail("ack: 1 field expected (SEQ), got " + std::to_string(f.size() - 1));
    BrowserMessage m;
    if (!integer(f[1], 1, INT64_C(1) << 52, &m.seq)) return bad("ack: SEQ", f[1], "is not a positive integer");
    m.kind = BrowserMessage::Kind::kAck;
    return m;
  }
  return bad("unknown message", f[0], "(p, l, k, c, r or a)");
}

}  // namespace palpate
