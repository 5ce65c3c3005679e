#include "runtime/session/through_watch.h"

#include <algorithm>

#include "runtime/session/surface_queries.h"

namespace palpate {
namespace {

// a free tool or a held proxy counts as through the surface deeper than this beyond what the material has moved
constexpr double kThroughTolerance_m = 5e-4;

}  // namespace

void ThroughWatch::tick(const HapticSample& s) {
  if (scene_.mode != InteractionMode::kTouch) return;
  const bool free = s.contact == ContactState::kFree;
  const Vec3& p = free ? s.tool_pos_m : s.god_pos_m;
  // a point on the deformed surface lies at most the material's move under the rest one (a sphere's centre a radius
  // above it), and a blended patch between two frames' surfaces
  const double reach_m = moved_m_ + scene_.device.tool_radius_m + kThroughTolerance_m;
  if (!model_.closed) {
    open_tick(free, p, reach_m, s.t_s);
    return;
  }
  // the last answer holds while the point stays this near where it was asked (a proxy sliding on the surface is
  // asked about once or twice a frame, not every tick)
  if (still_m_ > 0.0 && (p - at_m_).norm() < still_m_) return;
  at_m_ = p;
  if (depth_inside(model_, p, reach_m, &still_m_) == 0.0) return;
  ++(free ? stats_->tool_inside_ticks : stats_->proxy_inside_ticks);
  if (stats_->through_first_t_s < 0.0) stats_->through_first_t_s = s.t_s;
}

void ThroughWatch::open_tick(bool free, const Vec3& p, double reach_m, double t_s) {
  if (!p.allFinite()) return;
  if (have_path_ && (path_crossings(model_, path_at_m_, p, &ids_) & 1) != 0) path_odd_ = !path_odd_;
  path_at_m_ = p;
  have_path_ = true;
  if (!path_odd_) return;
  // on the surface's other side: through it once away from it (near it, a dent may hold the point there)
  const auto hit = nearest_surface_point(model_, p);
  if (!hit || !(hit->distance_m > reach_m)) return;
  ++(free ? stats_->tool_inside_ticks : stats_->proxy_inside_ticks);
  if (stats_->through_first_t_s < 0.0) stats_->through_first_t_s = t_s;
}

void ThroughWatch::frame(const HapticSample& latest, const Lattice* lat, double t_s) {
  if (scene_.mode != InteractionMode::kTouch || latest.contact != ContactState::kFree) return;
  if (proven_depth_inside(model_, latest.tool_pos_m, 0.0) == 0.0) return;  // a few cells decide the usual case
  double moved = 0.0;
  if (lat)
    for (std::size_t i = 0; i < lat->num_nodes(); ++i) moved = std::max(moved, (lat->x_m[i] - lat->rest_m[i]).norm());
  const double depth = proven_depth_inside(model_, latest.tool_pos_m, moved + scene_.device.tool_radius_m);
  if (depth == 0.0) return;
  if (stats_->tool_inside_frames++ == 0) {
    stats_->tool_inside_first_t_s = t_s;
    stats_->tool_inside_depth_m = depth;
  }
}

}  // namespace palpate
