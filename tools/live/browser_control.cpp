#include "tools/live/browser_control.h"

#include <algorithm>
#include <cstdio>

#include "core/clock.h"
#include "tools/live/browser_message.h"

namespace palpate {
namespace {

void keep(std::deque<double>* window, double v, std::size_t most) {
  window->push_back(v);
  while (window->size() > most) window->pop_front();
}

nlohmann::json percentiles(const std::deque<double>& w) {
  if (w.empty()) return {{"n", 0}};
  std::vector<double> v(w.begin(), w.end());
  std::sort(v.begin(), v.end());
  auto at = [&v](double q) { return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)]; };
  return {{"n", v.size()}, {"p50", at(0.5)}, {"p99", at(0.99)}, {"max", v.back()}};
}

}  // namespace

BrowserControl::BrowserControl(HttpServer* http, BrowserLink* link) : http_(http), link_(link) {
  http_->set_websocket({[this](int64_t id, const HttpRequest&) { open(id); },
                        [this](int64_t id, WsOpcode op, std::string_view text) {
                          if (op == WsOpcode::kText) message(id, text);
                          else http_->ws_close(id, kWsCloseUnsupported, "binary messages are not used");
                        },
                        [this](int64_t id, const std::string& why) { close(id, why); }});
}

std::string BrowserControl::hello(int64_t id) const {
  const bool control = !pages_.empty() && pages_.front() == id;
  return nlohmann::json{{"t", "hello"}, {"role", control ? "control" : "watch"}}.dump();
}

void BrowserControl::open(int64_t id) {
  pages_.push_back(id);
  if (pages_.size() == 1) {
    ++controllers_;
    last_seq_ = 0;
  }
  http_->ws_send(id, hello(id));
}

void BrowserControl::message(int64_t id, std::string_view text) {
  const BrowserMessage m = parse_browser_message(text);
  if (m.kind == BrowserMessage::Kind::kError) {
    // garbage closes the socket (and, for the controller, releases the device)
    ++refused_;
    last_refusal_ = m.reason;
    http_->ws_close(id, kWsClosePolicy, m.reason);
    return;
  }
  const bool control = !pages_.empty() && pages_.front() == id;
  if (m.kind == BrowserMessage::Kind::kLatency) {
    if (!control) return;
    if (m.force_ms >= 0.0) keep(&page_force_ms_, m.force_ms, kWindow);
    if (m.frame_ms >= 0.0) keep(&page_frame_ms_, m.frame_ms, kWindow);
    return;
  }
  if (!control) {
    ++ignored_;  // a watching page cannot steer
    return;
  }
  if (m.seq <= last_seq_) {
    ++ignored_;  // out of order or repeated
    return;
  }
  last_seq_ = m.seq;
  ++messages_;
  BrowserInput in;
  in.seq = m.seq;
  in.x = m.x;
  in.y = m.y;
  in.depth = m.depth;
  in.buttons = m.buttons;
  in.received_ns = monotonic_ns();
  link_->post(in);
}

void BrowserControl::close(int64_t id, const std::string& /*why*/) {
  const auto it = std::find(pages_.begin(), pages_.end(), id);
  if (it == pages_.end()) return;
  const bool was_control = it == pages_.begin();
  pages_.erase(it);
  if (!was_control) return;
  link_->release();
  last_seq_ = 0;
  // the oldest watcher takes over (it starts its own message numbers)
  if (!pages_.empty()) {
    ++controllers_;
    http_->ws_send(pages_.front(), hello(pages_.front()));
  }
}

void BrowserControl::tick(int64_t frame) {
  const BrowserFeedback& fb = link_->feedback();
  if (fb.seq != fed_seq_ && fb.seq > 0) {
    fed_seq_ = fb.seq;
    keep(&server_us_, static_cast<double>(fb.input_to_force_ns) * 1e-3, kWindow);
  }
  if (pages_.empty()) return;
  char text[256];
  std::snprintf(text, sizeof text,
                "{\"t\":\"f\",\"f\":[%.4f,%.4f,%.4f],\"fv\":[%.4f,%.4f,%.4f],\"hv\":[%.4f,%.4f,%.4f],\"scale\":%.3f,"
                "\"s\":%lld,\"k\":%lld}",
                fb.force_N.x(), fb.force_N.y(), fb.force_N.z(), fb.force_view_N.x(), fb.force_view_N.y(),
                fb.force_view_N.z(), fb.handle_view.x(), fb.handle_view.y(), fb.handle_view.z(), fb.force_scale,
                static_cast<long long>(fb.seq), static_cast<long long>(frame));
  for (const int64_t id : pages_) http_->ws_send(id, text);  // a page that cannot keep up misses some
}

nlohmann::json BrowserControl::stats() {
  const BrowserFeedback& fb = link_->feedback();
  return {{"pages", pages_.size()},
          {"controlled", !pages_.empty() && link_->live()},
          {"controllers", controllers_},
          {"messages", messages_},
          {"ignored", ignored_},
          {"refused", refused_},
          {"last_refusal", last_refusal_},
          {"seq", fb.seq},
          {"force_N", {fb.force_N.x(), fb.force_N.y(), fb.force_N.z()}},
          {"force_scale", fb.force_scale},
          {"handle_m", {fb.handle_m.x(), fb.handle_m.y(), fb.handle_m.z()}},
          {"input_to_force_us", percentiles(server_us_)},
          {"page_input_to_force_ms", percentiles(page_force_ms_)},
          {"page_input_to_frame_ms", percentiles(page_frame_ms_)}};
}

}  // namespace palpate
