#include "tools/session/view_style.h"

#include <algorithm>
#include <cmath>

#include "render/annotate.h"

namespace palpate {

ViewStyle::ViewStyle(const Scene& scene, const Model& model) : scene_(scene) {
  if (!colors_by_displacement(scene)) return;
  range_m_ = scene.render.color_range_m;
  planned_ = range_m_ > 0.0;
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const Vec3& v : model.rest.vertices_m) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double size = (hi - lo).allFinite() ? (hi - lo).maxCoeff() : 0.0;
  floor_m_ = nice_ceil(std::max(1e-3 * size, 1e-6));
  if (!planned_) range_m_ = floor_m_;
}

void ViewStyle::follow(double max_displacement_m) {
  if (planned_ || !colors_by_displacement(scene_) || !std::isfinite(max_displacement_m)) return;
  range_m_ = std::max(range_m_, nice_ceil(max_displacement_m));
}

void ViewStyle::apply(const HapticSample& latest, FrameView* view) const {
  view->color_range_m = colors_by_displacement(scene_) ? range_m_ : 0.0;
  view->show_force = scene_.render.force_arrow && latest.contact != ContactState::kFree;
  view->force_N = latest.force_N;
  view->force_scale_N = scene_.device.max_force_N;
  view->show_legend = scene_.render.legend;
}

}  // namespace palpate
