// Force shading (Morgenbesser and Srinivasan): the coupling's spring turned about the device from the facets' push
// toward the smooth normal at the contact point. Part of the servo (haptics/servo/servo.h). Thread: servo.
#include <algorithm>
#include <cmath>

#include "haptics/force/proxy_solver.h"
#include "haptics/servo/servo.h"

namespace palpate {
namespace {

// force shading turns the spring's force by at most this much a tick (N): a turn is felt as a step of |F| times its
// angle (following a smooth surface it turns by |F| v / R a second, 0.3 mN a tick at 1 N and 30 mm/s on a 10 cm
// radius)
constexpr double kShadeStep_N = 0.005;

}  // namespace

void Servo::update_shading(const LocalModel& m, const Vec3& c, int slot, const Vec3& bary, const Vec3& tool, double r,
                           double path_m) noexcept {
  // the facets' push: from the device to the proxy they alone would hold, bounded as the proxy is (with friction, a
  // companion god-object without it, so the friction's pull across the surface is not taken for the surface's turn)
  Vec3 at = c;
  if (params_.friction.on()) {
    Vec3 from = shade_free_m_;
    push_out(m, r, contact_normal_, 4, &from);
    int a = 0;
    at = shade_free_m_ = god_object_move(m, from, tool, r, contact_normal_, &a, path_m);
    slot = -1;  // (its contact point is not the proxy's)
  }
  // the force follows its target by at most kShadeStep_N a tick: where the contact stops being one convex spot, or
  // the push changes face while the proxy lags the device, the target turns at once and the force does not.
  // Frictionless, the spring is the push and the force's direction is what follows its target (a point rolling
  // over a facet edge turns the spring in a few bounded steps; the rotation onto the smooth normal turns back as
  // fast, and the force stays on it); with friction, the rotation itself (the push may jump where the spring,
  // held by friction, does not: a companion that leaves the surface, or rolls over a thin part's edge)
  const Vec3 push = (at - tool).normalized();
  const Vec3 target = push.allFinite() ? shaded_normal(m, at, slot, bary, tool, r) : push;
  const double step_rad = kShadeStep_N / std::max(params_.coupling_N_per_m * (c - tool).norm(), 1e-9);
  if (!params_.friction.on()) {
    if (push.allFinite() && target.allFinite()) {
      if (!(shade_n_.squaredNorm() > 0.0)) shade_n_ = shade_push_ = push;
      // as far again as the push itself turned (the turn the facets alone would give the force: round a sharp edge
      // the target is the push, and the force follows it at once)
      const double angle = std::acos(std::clamp(shade_n_.dot(target), -1.0, 1.0));
      const double most = step_rad + std::acos(std::clamp(shade_push_.dot(push), -1.0, 1.0));
      shade_push_ = push;
      const Vec3 across = target - shade_n_.dot(target) * shade_n_;
      shade_n_ = angle > most && across.squaredNorm() > 0.0
                     ? Vec3(std::cos(most) * shade_n_ + std::sin(most) * across.normalized())
                     : target;
      shade_ = Quat::FromTwoVectors(push, shade_n_);
    }
  } else {
    const Quat aim = push.allFinite() && target.allFinite() ? Quat::FromTwoVectors(push, target) : Quat::Identity();
    const double angle = shade_.angularDistance(aim);
    shade_ = angle > step_rad ? shade_.slerp(step_rad / angle, aim) : aim;
  }
  if (!shade_.coeffs().allFinite()) shade_ = Quat::Identity();
}

Vec3 Servo::shaded_normal(const LocalModel& m, const Vec3& at, int slot, const Vec3& bary, const Vec3& tool,
                          double r) const noexcept {
  const Vec3 push = (at - tool).normalized();
  if (!push.allFinite()) return push;
  Vec3 b = bary;
  if (slot < 0) {
    Vec3 q = Vec3::Zero();
    if (!closest_on_patch(m, at, &slot, &q, &b, &contact_normal_)) return push;
  }
  const auto& n = m.shade_normal[slot];
  const Vec3 smooth = b[0] * n[0] + b[1] * n[1] + b[2] * n[2];
  if (!(smooth.squaredNorm() > 0.0)) return push;  // (a patch without shading normals)
  const Vec3 ns = smooth.normalized();
  // a crease or a dent the tool fills is felt as its faces hold it: the contact point's smooth normal is one of
  // several there (and flips between them as the nearest face does). (A point rolls round an edge in bounded steps,
  // lagging the device: the faces within a step's reach of it hold it.)
  const bool point = !(params_.tool_radius_m > 0.0);
  const double reach = point && params_.coupling_N_per_m > 0.0 ? r + kPointRoll_N_per_tick / params_.coupling_N_per_m
                                                               : r * (1.0 + 1e-6) + 1e-10;
  if (!convex_contact(m, at, reach, contact_normal_, point)) return push;
  // in full while the two are close; not at all from half the crease angle, where the contact point may lie on either
  // side of a crease (a sharp edge the proxy rolls round), whose smooth normals differ
  const double w = std::clamp((push.dot(ns) - shade_none_cos_) / (shade_full_cos_ - shade_none_cos_), 0.0, 1.0);
  const Vec3 out = (push + w * (ns - push)).normalized();
  return out.allFinite() ? out : push;
}

}  // namespace palpate
