#include "haptics/devices/scripted_device.h"

#include <algorithm>
#include <cmath>

namespace palpate {

ScriptedDevice::ScriptedDevice(const DeviceSpecs& specs, const HandSpec& hand, std::vector<Keyframe> keys)
    : specs_(specs), hand_(hand), keys_(std::move(keys)) {
  if (!keys_.empty()) {
    pos_m_ = keys_.front().pos_m;
    t_s_ = keys_.front().t_s;
  }
}

void ScriptedDevice::target(double t_s, Vec3* pos_m, bool* button) const noexcept {
  if (keys_.empty()) {
    *pos_m = Vec3::Zero();
    *button = false;
    return;
  }
  if (t_s <= keys_.front().t_s) {
    *pos_m = keys_.front().pos_m;
    *button = keys_.front().button;
    return;
  }
  // the last key at or before t_s
  auto it = std::upper_bound(keys_.begin(), keys_.end(), t_s, [](double t, const Keyframe& k) { return t < k.t_s; });
  const Keyframe& a = *(it - 1);
  *button = a.button;
  if (it == keys_.end()) {
    *pos_m = a.pos_m;
    return;
  }
  const double u = (t_s - a.t_s) / (it->t_s - a.t_s);
  *pos_m = a.pos_m + u * (it->pos_m - a.pos_m);
}

Quat ScriptedDevice::orientation_at(double t_s) const noexcept {
  if (keys_.empty()) return Quat::Identity();
  if (t_s <= keys_.front().t_s) return keys_.front().orientation;
  auto it = std::upper_bound(keys_.begin(), keys_.end(), t_s, [](double t, const Keyframe& k) { return t < k.t_s; });
  if (it == keys_.end()) return keys_.back().orientation;
  const Keyframe& a = *(it - 1);
  return a.orientation.slerp((t_s - a.t_s) / (it->t_s - a.t_s), it->orientation);
}

bool ScriptedDevice::read(double t_s, DevicePose* out) noexcept {
  // hand: m a = k (target - x) - b v + F_device; the hand is continuous, the device force is held between
  // servo ticks (zero-order hold), so the hand is integrated in steps ten times finer than a 1 kHz period
  constexpr double kMaxStep_s = 1e-4;
  while (t_s_ < t_s - 1e-12) {
    const double h = std::min(kMaxStep_s, t_s - t_s_);
    Vec3 goal;
    bool button = false;
    target(t_s_ + h, &goal, &button);
    const Vec3 f = hand_.stiffness_N_per_m * (goal - pos_m_) - hand_.damping_Ns_per_m * vel_m_per_s_ + force_N_;
    vel_m_per_s_ += h * f / hand_.mass_kg;
    pos_m_ += h * vel_m_per_s_;
    t_s_ += h;
  }
  Vec3 goal;
  bool button = false;
  target(t_s, &goal, &button);
  out->pos_m = pos_m_;
  out->orientation = orientation_at(t_s);
  out->buttons = button ? 1u : 0u;
  return true;
}

}  // namespace palpate
