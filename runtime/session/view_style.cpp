#include "runtime/session/view_style.h"

#include <algorithm>
#include <cmath>

#include "core/aabb.h"
#include "render/annotate.h"

namespace palpate {

namespace {
constexpr double kTraceSeconds = 2.0;  // the force trace's span
}  // namespace

void ViewStyle::note_force(double force_N) {
  if (!scene_.render.force_trace) return;
  if (trace_.size() >= trace_frames_) trace_.erase(trace_.begin());
  trace_.push_back(static_cast<float>(force_N));
}

ViewStyle::ViewStyle(const Scene& scene, const Model& model) : scene_(scene) {
  trace_frames_ = static_cast<std::size_t>(std::max(2.0, std::round(kTraceSeconds * scene.rates.frame_hz)));
  trace_.reserve(trace_frames_);
  const Aabb box = Aabb::of(model.rest.vertices_m);
  const Vec3 &lo = box.min_m, &hi = box.max_m;
  const double size = box.extent().allFinite() ? box.extent().maxCoeff() : 0.0;
  // the floor: at the model's lowest point, three times as wide as the model and centred under it
  if (size > 0.0 && scene.render.floor) {
    closed_ = scene.mode != InteractionMode::kCut && (model.closed || closed_surface(model.rest, model.adjacency));
    ground_z_m_ = lo.z();
    ground_half_m_ = 1.5 * size;
    ground_centre_m_ = 0.5 * (lo + hi);
  }
  if (colors_by_strain(scene)) {
    range_ = scene.render.strain_range;
    planned_ = range_ > 0.0;
    if (!planned_) range_ = 0.01;  // followed from 1 %
    return;
  }
  if (!colors_by_displacement(scene)) return;
  range_ = scene.render.color_range_m;
  planned_ = range_ > 0.0;
  if (!planned_) range_ = nice_ceil(std::max(1e-3 * size, 1e-6));
}

double ViewStyle::largest_displacement_m(const FrameView& view) {
  if (!view.vertices_m || !view.rest_m) return 0.0;
  const auto& v = *view.vertices_m;
  const auto& rest = *view.rest_m;
  double most = 0.0;
  auto at = [&](std::size_t i) {
    if (i < v.size() && i < rest.size()) most = std::max(most, (v[i] - rest[i]).norm());
  };
  if (view.moving_vertices) {
    for (int32_t i : *view.moving_vertices) at(static_cast<std::size_t>(i));
  } else {
    for (std::size_t i = 0; i < v.size(); ++i) at(i);
  }
  return most;
}

double ViewStyle::largest_strain(const FrameView& view) {
  if (!view.vertex_value) return 0.0;
  const auto& e = *view.vertex_value;
  double most = 0.0;
  auto at = [&](std::size_t i) {
    if (i < e.size()) most = std::max(most, static_cast<double>(e[i]));
  };
  if (view.moving_vertices) {
    for (int32_t i : *view.moving_vertices) at(static_cast<std::size_t>(i));
  } else {
    for (std::size_t i = 0; i < e.size(); ++i) at(i);
  }
  return most;
}

void ViewStyle::observe(const FrameView& view) {
  const double most = largest_displacement_m(view);
  if (std::isfinite(most)) shown_max_m_ = std::max(shown_max_m_, most);
  const double strain = largest_strain(view);
  if (std::isfinite(strain)) shown_max_strain_ = std::max(shown_max_strain_, strain);
  if (planned_) return;
  if (colors_by_strain(scene_) && std::isfinite(strain)) range_ = std::max(range_, nice_ceil(strain));
  else if (colors_by_displacement(scene_) && std::isfinite(most)) range_ = std::max(range_, nice_ceil(most));
}

void ViewStyle::apply(const HapticSample& latest, FrameView* view) const {
  view->color_range_m = colors_by_displacement(scene_) ? range_ : 0.0;
  view->strain_range = colors_by_strain(scene_) ? range_ : 0.0;
  view->show_force = scene_.render.force_arrow && latest.contact != ContactState::kFree;
  view->force_N = latest.force_N;
  view->force_scale_N = scene_.render.force_arrow ? scene_.device.max_force_N : 0.0;
  view->show_legend = scene_.render.legend;
  if (scene_.render.force_trace && scene_.device.max_force_N > 0.0) {
    view->force_trace = &trace_;
    view->force_trace_max_N = scene_.device.max_force_N;
    view->force_trace_s = kTraceSeconds;
    view->force_trace_frames = trace_frames_;
  }
  if (scene_.render.floor && ground_half_m_ > 0.0) {
    view->floor_z_m = ground_z_m_;
    view->floor_half_m = ground_half_m_;
    view->floor_centre_m = ground_centre_m_;
    view->closed_surface = closed_;
  }
}

}  // namespace palpate
