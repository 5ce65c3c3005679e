#include "runtime/live/browser_control.h"

#include <algorithm>
#include <cstdio>

#include "core/clock.h"
#include "core/scene_controls.h"
#include "runtime/live/browser_message.h"

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

bool query_has_token(std::string_view query, std::string_view token) {
  if (token.empty()) return false;
  while (!query.empty()) {
    const auto amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    if (pair.substr(0, 6) == "token=") {
      const std::string_view given = pair.substr(6);
      if (given.size() != token.size()) return false;
      unsigned diff = 0;
      for (std::size_t i = 0; i < token.size(); ++i)
        diff |= static_cast<unsigned>(static_cast<unsigned char>(given[i]) ^ static_cast<unsigned char>(token[i]));
      return diff == 0;
    }
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return false;
}

BrowserControl::BrowserControl(HttpServer* http, BrowserLink* link, BrowserControlParams params)
    : http_(http), link_(link), params_(std::move(params)) {
  if (params_.scene) controls_ = scene_controls(*params_.scene);
  WsCallbacks cb;
  cb.open = [this](int64_t id, const HttpRequest& req) { open(id, req); };
  cb.message = [this](int64_t id, WsOpcode op, std::string_view text) {
    if (op == WsOpcode::kText) message(id, text);
    else http_->ws_close(id, kWsCloseUnsupported, "binary messages are not used");
  };
  cb.close = [this](int64_t id, const std::string& why) { close(id, why); };
  cb.evict = [this] { return evict(); };
  http_->set_websocket(std::move(cb));
}

BrowserControl::Page* BrowserControl::find(int64_t id) {
  for (Page& p : pages_)
    if (p.id == id) return &p;
  return nullptr;
}

std::string BrowserControl::hello(const Page& page) const {
  nlohmann::json j{{"t", "hello"},
                   {"role", page.id == controller_ ? "control" : "watch"},
                   {"steer", page.may_steer},
                   {"send_ms", params_.send_ms}};
  if (params_.scene) {
    const ControlLimits l = control_limits(*params_.scene);
    nlohmann::json modes = nlohmann::json::array();
    for (const InteractionMode m : l.modes) modes.push_back(mode_name(m));
    j["limits"] = {{"modes", modes},
                   {"stiffness", {l.stiffness_lo, l.stiffness_hi}},
                   {"radius_mm", {1e3 * l.radius_lo_m, 1e3 * l.radius_hi_m}},
                   {"sphere", params_.scene->device.sphere_tool},
                   {"young_modulus_kPa", l.material ? 1e-3 * l.young_modulus_Pa : 0.0}};
    j["controls"] = nlohmann::json::parse(controls_message())["controls"];
  }
  if (!page.may_steer)
    j["why"] = "this server listens beyond loopback: only a page opened with its token may steer (the address "
               "palpate printed, ending ?token=...)";
  return j.dump();
}

void BrowserControl::give_control(Page* page, int64_t now_ns) {
  const int64_t old = controller_;
  controller_ = page->id;
  control_since_ns_ = now_ns;
  unheard_ = 0;  // a new page's control anchors afresh anyway
  ++session_;
  ++controllers_;
  if (old >= 0 && old != page->id)
    if (const Page* was = find(old)) http_->ws_send(was->id, hello(*was));
  http_->ws_send(page->id, hello(*page));
}

bool BrowserControl::controller_stale(int64_t now_ns) const {
  if (controller_ < 0) return true;
  int64_t last = control_since_ns_;
  for (const Page& p : pages_)
    if (p.id == controller_) last = std::max(last, p.last_pose_ns);
  return static_cast<double>(now_ns - last) > params_.stale_ms * 1e6;
}

void BrowserControl::open(int64_t id, const HttpRequest& request) {
  Page p;
  p.id = id;
  p.may_steer = params_.token.empty() || query_has_token(request.query, params_.token);
  p.opened_ns = monotonic_ns();
  pages_.push_back(p);
  if (controller_ < 0 && p.may_steer) give_control(&pages_.back(), p.opened_ns);
  else http_->ws_send(id, hello(pages_.back()));
  if (!ended_.empty()) http_->ws_send(id, ended_);
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
  if (m.kind == BrowserMessage::Kind::kAlive) return;  // keeps the socket, is not steering
  const bool control = id == controller_;
  if (m.kind == BrowserMessage::Kind::kLatency) {
    if (!control) return;
    if (m.force_ms >= 0.0) keep(&page_force_ms_, m.force_ms, kWindow);
    if (m.frame_ms >= 0.0) keep(&page_frame_ms_, m.frame_ms, kWindow);
    return;
  }
  Page* page = find(id);
  if (m.kind == BrowserMessage::Kind::kAck) {
    if (control && m.seq == unheard_) unheard_ = 0;
    return;
  }
  if (m.kind == BrowserMessage::Kind::kControls || m.kind == BrowserMessage::Kind::kReset) {
    if (!page || !page->may_steer || !control || !params_.scene) {
      ++ignored_;  // only the steering page changes what the servo does
      return;
    }
    apply_control(page, m, monotonic_ns());
    return;
  }
  if (control && unheard_ > 0 && page) {
    // a pose the steering page made before it heard of the change (from where the tool was): the device anchors at
    // its first pose after the acknowledgement instead, made from where the tool went
    page->last_seq = std::max(page->last_seq, m.seq);
    return;
  }
  if (!page || !page->may_steer || m.seq <= page->last_seq) {
    ++ignored_;  // a page without the token, or a repeated or out-of-order pose
    return;
  }
  const int64_t now = monotonic_ns();
  if (!control) {
    // a page that steers takes control from one silent past the watchdog (or from none); otherwise it watches
    if (!controller_stale(now)) {
      ++ignored_;
      return;
    }
    ++takeovers_;
    give_control(page, now);
  }
  page->last_seq = m.seq;
  page->last_pose_ns = now;
  ++messages_;
  BrowserInput in;
  in.seq = m.seq;
  in.x = m.x;
  in.y = m.y;
  in.depth = m.depth;
  in.buttons = m.buttons;
  in.received_ns = now;
  in.session = session_;
  link_->post(in);
}

std::string BrowserControl::controls_message() const {
  return nlohmann::json{{"t", "controls"},
                        {"controls",
                         {{"seq", controls_.seq},
                          {"mode", mode_name(controls_.mode)},
                          {"stiffness", controls_.stiffness_scale},
                          {"radius_mm", 1e3 * controls_.tool_radius_m},
                          {"resets", controls_.resets}}}}
      .dump();
}

void BrowserControl::apply_control(Page* page, const BrowserMessage& m, int64_t now_ns) {
  Controls c = controls_;
  if (m.kind == BrowserMessage::Kind::kReset) {
    ++c.resets;
  } else {
    c.mode = m.mode;
    c.stiffness_scale = m.stiffness_scale;
    c.tool_radius_m = m.tool_radius_m;
    if (c.mode == controls_.mode && c.stiffness_scale == controls_.stiffness_scale &&
        c.tool_radius_m == controls_.tool_radius_m)
      return;  // nothing changes: the model is not started again
  }
  if (const std::string why = refuse_controls(*params_.scene, c); !why.empty()) {
    ++control_refusals_;
    last_control_refusal_ = why;
    http_->ws_send(page->id, nlohmann::json{{"t", "refused"}, {"why", why}}.dump());
    return;
  }
  page->last_pose_ns = now_ns;  // a change of what the servo does is steering
  c.seq = controls_.seq + 1;
  controls_ = c;
  ++control_changes_;
  unheard_ = c.seq;
  link_->post_controls(c);
  const std::string said = controls_message();
  for (const Page& p : pages_) http_->ws_send(p.id, said);
}

void BrowserControl::close(int64_t id, const std::string& /*why*/) {
  const auto it = std::find_if(pages_.begin(), pages_.end(), [id](const Page& p) { return p.id == id; });
  if (it == pages_.end()) return;
  pages_.erase(it);
  if (id != controller_) return;
  link_->release();
  controller_ = -1;
  // the oldest page that may steer is offered control (it anchors where the tool is when it first moves)
  for (Page& p : pages_)
    if (p.may_steer) {
      give_control(&p, monotonic_ns());
      break;
    }
}

int64_t BrowserControl::evict() {
  // the page longest without steering (its opening counts), never a controller that steered within the watchdog
  const int64_t now = monotonic_ns();
  const bool keep_controller = !controller_stale(now);
  const Page* pick = nullptr;
  for (const Page& p : pages_) {
    if (p.id == controller_ && keep_controller) continue;
    const int64_t active = std::max(p.opened_ns, p.last_pose_ns);
    if (!pick || active < std::max(pick->opened_ns, pick->last_pose_ns)) pick = &p;
  }
  if (!pick) return -1;
  ++evicted_;
  return pick->id;
}

void BrowserControl::run_ended(const std::string& out_dir) {
  if (!ended_.empty()) return;
  ended_ = nlohmann::json{{"t", "ended"}, {"out", out_dir}}.dump();
  for (const Page& p : pages_) http_->ws_send(p.id, ended_);
}

void BrowserControl::tick(int64_t frame) {
  const BrowserFeedback& fb = link_->feedback();
  if (fb.seq != fed_seq_ && fb.seq > 0) {
    fed_seq_ = fb.seq;
    keep(&server_us_, static_cast<double>(fb.input_to_force_ns) * 1e-3, kWindow);
  }
  if (pages_.empty() || !ended_.empty()) return;
  char text[384];
  std::snprintf(text, sizeof text,
                "{\"t\":\"f\",\"f\":[%.4f,%.4f,%.4f],\"fv\":[%.4f,%.4f,%.4f],\"hv\":[%.4f,%.4f,%.4f],"
                "\"hs\":[%.4f,%.4f],\"mm\":[%.2f,%.2f,%.2f],\"scale\":%.3f,\"e\":%d,\"s\":%lld,\"k\":%lld,\"n\":%lld,\"c\":%lld}",
                fb.force_N.x(), fb.force_N.y(), fb.force_N.z(), fb.force_view_N.x(), fb.force_view_N.y(),
                fb.force_view_N.z(), fb.handle_view.x(), fb.handle_view.y(), fb.handle_view.z(), fb.handle_screen.x(),
                fb.handle_screen.y(), fb.view_half_mm.x(), fb.view_half_mm.y(), fb.view_half_mm.z(), fb.force_scale,
                fb.engaged ? 1 : 0, static_cast<long long>(fb.seq), static_cast<long long>(frame),
                static_cast<long long>(fb.ticks), static_cast<long long>(fb.controls.seq));
  for (const Page& p : pages_) http_->ws_send(p.id, text);  // a page that cannot keep up misses some
}

nlohmann::json BrowserControl::stats() {
  const BrowserFeedback& fb = link_->feedback();
  return {{"pages", pages_.size()},
          {"controlled", controller_ >= 0 && link_->live()},
          {"controllers", controllers_},
          {"takeovers", takeovers_},
          {"evicted", evicted_},
          {"token_required", !params_.token.empty()},
          {"engaged", fb.engaged},
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
          {"page_input_to_frame_ms", percentiles(page_frame_ms_)},
          {"controls",
           {{"seq", fb.controls.seq},
            {"mode", mode_name(fb.controls.mode)},
            {"stiffness", fb.controls.stiffness_scale},
            {"radius_mm", 1e3 * fb.controls.tool_radius_m},
            {"resets", fb.controls.resets},
            {"changes", control_changes_},
            {"refused", control_refusals_},
            {"last_refusal", last_control_refusal_}}}};
}

}  // namespace palpate
