#include "runtime/record/scene_view.h"

#include <algorithm>
#include <cmath>

namespace palpate {

BrowserView browser_view(const Camera& cam, double aspect, double diagonal_m) {
  BrowserView v;
  v.centre_m = cam.target_m;
  v.forward = (cam.target_m - cam.eye_m).normalized();
  v.right = v.forward.cross(cam.up).normalized();
  v.up = v.right.cross(v.forward);
  v.half_height_m = (cam.target_m - cam.eye_m).norm() * std::tan(0.5 * cam.fov_y_deg * M_PI / 180.0);
  v.half_width_m = v.half_height_m * aspect;
  v.half_depth_m = 0.5 * diagonal_m;
  v.eye_m = cam.eye_m;
  v.tan_half_fov_y = std::tan(0.5 * cam.fov_y_deg * M_PI / 180.0);
  v.aspect = aspect;
  return v;
}

Camera scene_camera(const Scene& scene, const Aabb& model_box_m) {
  return scene_camera(scene, model_box_m, scene.device.driver);
}

Camera scene_camera(const Scene& scene, const Aabb& model_box_m, DeviceDriver driver) {
  Aabb box = model_box_m;
  // a scripted touch or pull: the tool where its keyframes put it too (a sphere above the model is drawn whole),
  // each held within a quarter of the model's diagonal of its box so a far start does not shrink the model
  if (driver == DeviceDriver::kScripted && scene.mode != InteractionMode::kCut &&
      !(scene.render.frame_radius_m > 0.0) && model_box_m.extent().allFinite()) {
    const Vec3 reach = Vec3::Constant(0.25 * model_box_m.extent().norm());
    const Vec3 r = Vec3::Constant(std::max(scene.device.tool_radius_m, 0.0));
    for (const Keyframe& k : scene.trajectory) {
      if (!k.pos_m.allFinite()) continue;
      const Vec3 p = k.pos_m.cwiseMax(model_box_m.min_m - reach).cwiseMin(model_box_m.max_m + reach);
      box.min_m = box.min_m.cwiseMin(p - r);
      box.max_m = box.max_m.cwiseMax(p + r);
    }
  }
  return Camera::framing_part(box.min_m, box.max_m,
                              static_cast<double>(scene.render.width) / scene.render.height, scene.render.view_from,
                              scene.render.look_at_m, scene.render.frame_radius_m);
}

}  // namespace palpate
