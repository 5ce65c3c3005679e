#include "haptics/devices/browser_device.h"

#include <algorithm>
#include <cmath>

#include "core/clock.h"
#include "haptics/force/force_limit.h"

namespace palpate {
namespace {

int64_t default_clock() { return monotonic_ns(); }

}  // namespace

BrowserDevice::BrowserDevice(const DeviceSpecs& specs, const HandSpec& hand, const BrowserParams& params,
                             BrowserLink* link, const Rates& rates, ClockFn clock)
    : specs_(specs), hand_(hand), params_(params), link_(link), rates_(rates), clock_(clock ? clock : default_clock) {}

Vec3 BrowserDevice::world_of(const BrowserInput& in) const noexcept {
  return view_.centre_m + in.x * view_.half_width_m * view_.right + in.y * view_.half_height_m * view_.up +
         in.depth * view_.half_depth_m * view_.forward;
}

Vec3 BrowserDevice::screen_of(const Vec3& p_m) const noexcept {
  const Vec3 d = p_m - view_.eye_m;
  const double z = d.dot(view_.forward);
  if (!(z > 1e-9) || !(view_.tan_half_fov_y > 0.0)) return Vec3(0.0, 0.0, z);
  const double h = z * view_.tan_half_fov_y;
  return Vec3(d.dot(view_.right) / (h * view_.aspect), d.dot(view_.up) / h, z);
}

namespace {

// a message that moved the pointer or changed the buttons since `from` (the page writes 4 decimals)
bool moved_since(const BrowserInput& in, const BrowserInput& from) noexcept {
  constexpr double kEps = 1e-7;
  return std::abs(in.x - from.x) > kEps || std::abs(in.y - from.y) > kEps || std::abs(in.depth - from.depth) > kEps ||
         in.buttons != from.buttons;
}

}  // namespace

// Thread: servo
bool BrowserDevice::read(double /*t_s*/, DevicePose* out) noexcept {
  const int64_t now = clock_();
  const double dt_s = rates_.servo_period_s();
  const double elapsed_s = last_ns_ > 0 ? std::clamp(static_cast<double>(now - last_ns_) * 1e-9, 0.0, 0.05) : 0.0;
  last_ns_ = now;
  if (!started_) set_start(view_.centre_m);
  if (const Controls& c = link_->take_controls(); c.seq > controls_.seq) {
    // the model starts again under new controls: the tool goes back to where it waited, the force fades out, and the
    // pointer anchors afresh with the next message (nothing moves until its user moves)
    controls_ = c;
    handle_m_ = target_m_ = from_m_ = to_m_ = start_m_;
    vel_m_per_s_.setZero();
    seg_s_ = 0.0;
    engaged_ = false;
    buttons_ = 0;
    reanchor_ = true;
    at_start_ = true;
  }
  out->controls = controls_;
  fb_.controls = controls_;
  const bool live = link_->live();
  const BrowserInput& in = link_->take();
  if (live && in.seq > 0 && (in.seq != seq_ || in.session != session_)) {
    const Vec3 p = world_of(in);
    if (!anchored_ || in.session != session_ || reanchor_) {
      reanchor_ = false;
      // a page's control begins (its first message, a page taking over, or one after the force faded out): the
      // pointer is anchored where the tool is held (the hand keeps holding it there), and nothing moves; the buttons
      // wait for the page to engage
      offset_m_ = target_m_ - p;
      from_m_ = to_m_ = target_m_;
      seg_s_ = 0.0;
      anchor_ = in;
      session_ = in.session;
      anchored_ = true;
      engaged_ = false;
      buttons_ = 0;
    } else {
      if (!engaged_ && moved_since(in, anchor_)) engaged_ = true;
      if (engaged_) at_start_ = false;
      // the interval between messages, smoothed, is the time the target takes to reach the new point
      const double gap_s = static_cast<double>(in.received_ns - last_rx_ns_) * 1e-9;
      counters_.max_gap_ms = std::max(counters_.max_gap_ms, gap_s * 1e3);
      if (gap_s > 0.0) interval_s_ += 0.25 * (std::clamp(gap_s, params_.min_interval_s, params_.max_interval_s) - interval_s_);
      from_m_ = target_m_;
      to_m_ = p + offset_m_;
      seg_start_ns_ = now;
      seg_s_ = interval_s_;
      if (engaged_) buttons_ = in.buttons;
    }
    seq_ = in.seq;
    last_in_ = in;
    last_rx_ns_ = in.received_ns;
    fb_.seq = seq_;
    fb_.input_to_force_ns = now - in.received_ns;
    ++counters_.messages;
  }
  // watchdog: a page gone or silent fades the force out; a live one that has moved fades it back in
  const bool stalled = seq_ > 0 && static_cast<double>(now - last_rx_ns_) * 1e-9 > params_.stall_s;
  if (stalled && !stalled_) ++counters_.stalls;
  stalled_ = stalled;
  if (was_live_ && !live) ++counters_.releases;
  was_live_ = live;
  const bool goal = anchored_ && engaged_ && live && !stalled;
  const double step = params_.fade_s > 0.0 ? elapsed_s / params_.fade_s : 1.0;
  scale_ = goal ? std::min(1.0, scale_ + step) : std::max(0.0, scale_ - step);
  // faded out for a page gone or silent: it engages again only with a message that moves from its last one (a
  // hidden tab's odd message, unchanged, brings nothing back); its anchor stays, so a motion sent after a pause is
  // not lost (a page taking over anchors afresh: a new session)
  if (scale_ == 0.0 && (stalled || !live) && engaged_) {
    engaged_ = false;
    anchor_ = last_in_;
  }
  fb_.engaged = anchored_ && engaged_;
  if (!anchored_ || (!goal && scale_ == 0.0)) {
    ++counters_.silent_ticks;
    fb_.force_scale = 0.0;
    return false;
  }
  // the target moves along its segment; the hand (mass, spring to the target, damper) is pushed by the device force
  const double u = seg_s_ > 0.0 ? std::clamp(static_cast<double>(now - seg_start_ns_) * 1e-9 / seg_s_, 0.0, 1.0) : 1.0;
  target_m_ = from_m_ + u * (to_m_ - from_m_);
  // (put back where it waited, the hand is not pushed by the force the servo lets go of)
  const Vec3 push = at_start_ ? Vec3::Zero() : force_N_;
  const Vec3 accel = (hand_.stiffness_N_per_m * (target_m_ - handle_m_) - hand_.damping_Ns_per_m * vel_m_per_s_ +
                      push) / hand_.mass_kg;
  vel_m_per_s_ += accel * dt_s;
  handle_m_ += vel_m_per_s_ * dt_s;
  out->pos_m = handle_m_;
  out->orientation = Quat::Identity();
  out->buttons = buttons_;
  out->force_scale = scale_;
  fb_.force_scale = scale_;
  return true;
}

// Thread: servo
void BrowserDevice::write_force(const Vec3& force_N) noexcept {
  force_N_ = limit_force(force_N.allFinite() ? force_N : Vec3::Zero(), specs_.max_force_N);
  fb_.force_N = force_N_;
  fb_.handle_m = handle_m_;
  fb_.target_m = target_m_;
  fb_.force_view_N = Vec3(force_N_.dot(view_.right), force_N_.dot(view_.up), force_N_.dot(view_.forward));
  const Vec3 d = handle_m_ - view_.centre_m;
  fb_.handle_view = Vec3(d.dot(view_.right) / view_.half_width_m, d.dot(view_.up) / view_.half_height_m,
                         d.dot(view_.forward) / view_.half_depth_m);
  fb_.handle_screen = screen_of(handle_m_);
  fb_.view_half_mm = Vec3(view_.half_width_m, view_.half_height_m, view_.half_depth_m) * 1e3;
  ++fb_.ticks;
  link_->publish(fb_);
}

nlohmann::json BrowserDevice::report() const {
  return {{"driver", "browser"},
          {"messages", counters_.messages},
          {"stalls", counters_.stalls},
          {"releases", counters_.releases},
          {"silent_ticks", counters_.silent_ticks},
          {"max_gap_ms", counters_.max_gap_ms},
          {"watchdog_ms", params_.watchdog_s() * 1e3},
          {"stall_ms", params_.stall_s * 1e3},
          {"fade_ms", params_.fade_s * 1e3}};
}

}  // namespace palpate
