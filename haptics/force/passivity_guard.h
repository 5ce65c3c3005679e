#pragma once
/// PassivityGuard: an energy-based passivity observer and controller on the device port (after Hannaford & Ryu):
/// it sums the energy the user puts into the virtual environment, and when the environment has returned more
/// than it received it adds just enough damping to dissipate the excess.

#include <cstdint>

#include "core/types.h"

namespace palpate {

/// Observer state and counters. Copyable. Thread: servo (filter is noexcept and allocation-free).
class PassivityGuard {
 public:
  /// max_damping_Ns_per_m bounds the damping the controller may add in one tick.
  explicit PassivityGuard(double max_damping_Ns_per_m = 20.0) : max_damping_Ns_per_m_(max_damping_Ns_per_m) {}

  /// Accounts the work of the force sent last tick over the tool's displacement since (dx_m), then returns
  /// the force to send now: force_N while the observed energy is >= 0, otherwise force_N - alpha * v with alpha
  /// sized to dissipate the deficit over one period (at most max_damping_Ns_per_m). max_step_N > 0: the added
  /// damping force changes by at most this a tick, so the controller switching on or off is no click (the observer
  /// accounts what was sent, so a deficit left by the slower start is dissipated on the next ticks).
  Vec3 filter(const Vec3& force_N, const Vec3& dx_m, double dt_s, double max_step_N = 0.0) noexcept {
    // energy into the environment: what the user did against the force that was actually held on the device
    energy_J_ -= last_sent_N_.dot(dx_m);
    const Vec3 v = dx_m / dt_s;
    const double v2 = v.squaredNorm();
    Vec3 damp = Vec3::Zero();
    if (energy_J_ < 0.0 && v2 > 1e-12) {
      double alpha = -energy_J_ / (dt_s * v2);
      if (alpha > max_damping_Ns_per_m_) alpha = max_damping_Ns_per_m_;
      damp = -alpha * v;
    }
    if (max_step_N > 0.0) {
      const Vec3 step = damp - damp_N_;
      const double len = step.norm();
      damp = len <= max_step_N ? damp : Vec3(damp_N_ + step * (max_step_N / len));
    }
    damp_N_ = damp;
    const double work = -damp.dot(v) * dt_s;  // expected over the next period
    if (damp.squaredNorm() > 0.0) {
      if (work > 0.0) dissipated_J_ += work;
      ++activations_;
    }
    const Vec3 out = force_N + damp;
    last_sent_N_ = out;
    return out;
  }
  /// Records the force that was finally sent (after clamping), for the next tick's accounting.
  void sent(const Vec3& force_N) noexcept { last_sent_N_ = force_N; }
  /// Forgets the observed energy (after a reset of the coupling).
  void reset() noexcept {
    energy_J_ = 0.0;
    last_sent_N_.setZero();
    damp_N_.setZero();
  }
  /// Observed energy in the environment, J (>= 0 while passive).
  double energy_J() const noexcept { return energy_J_; }
  /// Ticks on which damping was added.
  int64_t activations() const noexcept { return activations_; }
  /// Energy dissipated by the added damping, J.
  double dissipated_J() const noexcept { return dissipated_J_; }

 private:
  double max_damping_Ns_per_m_;
  double energy_J_ = 0.0;
  Vec3 last_sent_N_ = Vec3::Zero();
  Vec3 damp_N_ = Vec3::Zero();  // the damping force added last tick
  double dissipated_J_ = 0.0;
  int64_t activations_ = 0;
};

}  // namespace palpate
