#pragma once
/// The one force limit every path to a device applies: a non-finite force becomes zero, one longer than max_N is
/// scaled back to max_N along its direction. Servo-thread safe (no allocation, no throw).

#include <cmath>

#include "core/types.h"

namespace palpate {

inline Vec3 limit_force(const Vec3& force_N, double max_N) noexcept {
  const double mag = force_N.norm();
  if (!std::isfinite(mag)) return Vec3::Zero();
  return mag > max_N ? Vec3(force_N * (max_N / mag)) : force_N;
}

}  // namespace palpate
