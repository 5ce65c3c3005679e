#pragma once
/// Coulomb friction for a god-object proxy (the friction cone of the god-object renderers): the proxy sticks while
/// the device's pull across the surface stays within mu_s times the normal force, then slides, trailing the device
/// by the offset at which the coupling's force across the surface is mu_d times the normal force; it sticks again
/// once the device stops moving across the surface. At breakaway the trail comes down from the static cone to the
/// dynamic one at a bounded rate, so the drop is not a click. Thread: servo (noexcept, no allocation).

#include <algorithm>

#include "core/types.h"

namespace palpate {

/// Friction coefficients; both 0 = frictionless. Plain data.
struct FrictionParams {
  double static_coefficient = 0.0;    ///< mu_s: breakaway at mu_s F_n
  double dynamic_coefficient = 0.0;   ///< mu_d <= mu_s: sliding force mu_d F_n
  double stick_speed_m_per_s = 1e-3;  ///< a sliding proxy sticks again when the device moves across slower than this
  double trail_drop_m = 0.0;          ///< > 0: after breakaway the trail shrinks by at most this a tick (0: at once)
  /// Whether friction acts.
  bool on() const noexcept { return static_coefficient > 0.0 || dynamic_coefficient > 0.0; }
};

/// Stick/slide state carried between ticks. Plain data.
struct FrictionState {
  bool sliding = false;  ///< sliding, else sticking
  double trail_m = 0.0;  ///< sliding: the proxy's offset across the surface from the device
};

/// What the proxy does this tick. Plain data.
struct FrictionStep {
  bool stick = false;        ///< stay at the held position
  Vec3 goal = Vec3::Zero();  ///< otherwise: move toward this goal (the device, offset against the sliding)
};

/// The tick's friction from the held proxy `held`, the frictionless proxy `free` (where the surface alone would put
/// it: the god-object's move from `held` toward the device) and the device `tool` with its velocity. The cone is
/// taken along the surface the proxy moves on: F_n = k |free - tool| (the frictionless coupling), and the pull across
/// is k |held - free|, how far the surface alone would carry the held proxy. Sliding, the goal lies on the way from
/// `held` to `free`, mu_d |free - tool| short of `free`, so a tilted or curved surface (the dent the tool presses)
/// never turns a small change of the cone into a large move of the proxy.
inline FrictionStep friction_step(const FrictionParams& p, const Vec3& held, const Vec3& free, const Vec3& tool,
                                  const Vec3& tool_vel_m_per_s, FrictionState* st) noexcept {
  FrictionStep s;
  s.goal = free;
  const Vec3 normal_offset = free - tool;
  const double depth = normal_offset.norm();
  if (!(depth > 0.0)) return s;
  const Vec3 n = normal_offset / depth;
  const Vec3 across = held - free;  // the way back from where the surface alone would put the proxy
  const double pull = across.norm();
  if (!st->sliding) {
    if (pull <= p.static_coefficient * depth) {
      s.stick = true;
      return s;
    }
    st->sliding = true;
    st->trail_m = pull;
  }
  // the trail: the dynamic cone, reached from the breakaway at most trail_drop_m a tick
  const double cone = p.dynamic_coefficient * depth;
  st->trail_m = p.trail_drop_m > 0.0 ? std::max(cone, std::min(st->trail_m, pull) - p.trail_drop_m) : cone;
  if (pull <= st->trail_m) {
    // inside the sliding cone: the proxy stays; it sticks once the device stops moving across the surface
    s.stick = true;
    const Vec3 v_across = tool_vel_m_per_s - tool_vel_m_per_s.dot(n) * n;
    if (v_across.norm() < p.stick_speed_m_per_s) st->sliding = false;
    return s;
  }
  s.goal = free + (st->trail_m / pull) * across;
  return s;
}

}  // namespace palpate
