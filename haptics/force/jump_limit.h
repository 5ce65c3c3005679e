#pragma once
/// JumpLimit: a force step the device's motion does not explain (contact entry and release, grab and its release, a
/// region placed or moved, a cut starting or ending) is taken up as an offset that returns to zero at a stated rate, so
/// the hand never feels the step as a click. It changes nothing while no step is pending: a limit on jumps, not a
/// filter on the force of steady contact. Thread: servo.

#include <cmath>

#include "core/types.h"

namespace palpate {

/// Offset between the force sent and the force computed, returning to zero by at most rate_N_per_tick a tick.
class JumpLimit {
 public:
  /// Starts taking up the step from the force sent last tick to `computed` (an event on this tick).
  void absorb(const Vec3& sent_last_N, const Vec3& computed_N) noexcept { offset_N_ = sent_last_N - computed_N; }
  /// The force to send for `computed`; the offset shrinks by rate_N_per_tick first (rate <= 0: no limit).
  Vec3 apply(const Vec3& computed_N, double rate_N_per_tick) noexcept {
    if (!(rate_N_per_tick > 0.0)) {
      offset_N_.setZero();
      return computed_N;
    }
    const double len = offset_N_.norm();
    offset_N_ = len <= rate_N_per_tick ? Vec3::Zero() : Vec3(offset_N_ * ((len - rate_N_per_tick) / len));
    return computed_N + offset_N_;
  }
  /// The offset still pending (N).
  const Vec3& offset_N() const noexcept { return offset_N_; }
  /// Drops the pending offset.
  void reset() noexcept { offset_N_.setZero(); }

 private:
  Vec3 offset_N_ = Vec3::Zero();
};

}  // namespace palpate
