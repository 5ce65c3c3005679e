#include "render/camera.h"

#include <algorithm>
#include <cmath>

namespace palpate {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMinRadiusM = 0.01;  // half-size of the box used for degenerate input

}  // namespace

Camera Camera::framing(const Vec3& box_min_m, const Vec3& box_max_m, double aspect) {
  return framing(box_min_m, box_max_m, aspect, kDefaultViewFrom);
}

namespace {

// A camera looking from `from` at the sphere (center, radius_m), the sphere in the narrower field of view.
Camera framing_sphere(Vec3 center, double radius_m, double aspect, const Vec3& from) {
  if (!(aspect > 0.0) || !std::isfinite(aspect)) aspect = 1.0;
  Camera cam;
  if (!center.allFinite()) center.setZero();
  if (!std::isfinite(radius_m) || radius_m < kMinRadiusM) radius_m = kMinRadiusM;

  // the bounding sphere must fit in the narrower of the two fields of view
  const double half_fov_y = 0.5 * cam.fov_y_deg * kPi / 180.0;
  const double half_fov_x = std::atan(aspect * std::tan(half_fov_y));
  const double half_fov = std::min(half_fov_y, half_fov_x);
  const double distance_m = 1.05 * radius_m / std::sin(half_fov);

  const Vec3 direction = from.allFinite() && from.norm() > 1e-9 ? from.normalized() : kDefaultViewFrom.normalized();
  cam.target_m = center;
  cam.eye_m = center + distance_m * direction;
  // z up, unless the camera looks (nearly) along z: then +y is up in the image
  cam.up = direction.cross(Vec3::UnitZ()).norm() > 0.05 ? Vec3::UnitZ() : Vec3::UnitY();
  cam.near_m = std::max(distance_m - 2.0 * radius_m, 0.02 * distance_m);
  cam.far_m = distance_m + 3.0 * radius_m;
  return cam;
}

}  // namespace

Camera Camera::framing(const Vec3& box_min_m, const Vec3& box_max_m, double aspect, const Vec3& from) {
  return framing_sphere(0.5 * (box_min_m + box_max_m), 0.5 * (box_max_m - box_min_m).norm(), aspect, from);
}

Camera Camera::framing_part(const Vec3& box_min_m, const Vec3& box_max_m, double aspect, const Vec3& from,
                            const Vec3& look_at_m, double frame_radius_m) {
  if (!(frame_radius_m > 0.0) || !look_at_m.allFinite()) return framing(box_min_m, box_max_m, aspect, from);
  Camera cam = framing_sphere(look_at_m, frame_radius_m, aspect, from);
  // the rest of the model around the part stays drawn: the clip planes reach the box's farthest corner
  double reach_m = 0.0;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? box_max_m.x() : box_min_m.x(), (c & 2) ? box_max_m.y() : box_min_m.y(),
                      (c & 4) ? box_max_m.z() : box_min_m.z());
    if (corner.allFinite()) reach_m = std::max(reach_m, (corner - cam.target_m).norm());
  }
  const double distance_m = (cam.eye_m - cam.target_m).norm();
  cam.near_m = std::min(cam.near_m, std::max(distance_m - reach_m, 0.02 * distance_m));
  cam.far_m = std::max(cam.far_m, distance_m + 1.05 * reach_m);
  return cam;
}

Eigen::Matrix4d Camera::view_matrix() const {
  const Vec3 forward = (target_m - eye_m).normalized();
  Vec3 side = forward.cross(up);
  // up parallel to the view direction: pick any perpendicular
  if (side.squaredNorm() < 1e-12) side = forward.unitOrthogonal();
  side.normalize();
  const Vec3 true_up = side.cross(forward);
  Eigen::Matrix4d v = Eigen::Matrix4d::Identity();
  v.block<1, 3>(0, 0) = side.transpose();
  v.block<1, 3>(1, 0) = true_up.transpose();
  v.block<1, 3>(2, 0) = -forward.transpose();
  v(0, 3) = -side.dot(eye_m);
  v(1, 3) = -true_up.dot(eye_m);
  v(2, 3) = forward.dot(eye_m);
  return v;
}

Eigen::Matrix4d Camera::projection_matrix(double aspect) const {
  const double f = 1.0 / std::tan(0.5 * fov_y_deg * kPi / 180.0);
  Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
  p(0, 0) = f / aspect;
  p(1, 1) = f;
  p(2, 2) = (far_m + near_m) / (near_m - far_m);
  p(2, 3) = 2.0 * far_m * near_m / (near_m - far_m);
  p(3, 2) = -1.0;
  return p;
}

}  // namespace palpate
