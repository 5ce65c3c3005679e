#pragma once
/// Camera: a perspective look-at camera (world frame, z up by default).

#include <Eigen/Core>

#include "core/types.h"

namespace palpate {

/// The default direction framing() looks from: front (-y), right (+x), above (+z).
inline const Vec3 kDefaultViewFrom = Vec3(0.55, -1.0, 0.6);

/// Perspective look-at camera; plain data, copyable.
struct Camera {
  Vec3 eye_m = Vec3(0.0, -1.0, 0.0);  ///< eye position, metres
  Vec3 target_m = Vec3::Zero();       ///< point looked at (image centre), metres
  Vec3 up = Vec3::UnitZ();            ///< world up direction (unitless, need not be unit length)
  double fov_y_deg = 35;              ///< vertical field of view, degrees
  double near_m = 0.01;               ///< near clip distance, metres
  double far_m = 10.0;                ///< far clip distance, metres

  /// A camera looking at the box from the front-right-above (z up), whole box in view at the given aspect
  /// (width / height; non-positive or non-finite means 1). A degenerate box is framed as a 2 cm cube.
  static Camera framing(const Vec3& box_min_m, const Vec3& box_max_m, double aspect);
  /// The same, looking from `from` (a direction from the box's centre toward the eye; zero or non-finite means the
  /// default front-right-above); straight down or up takes +y as the image's up.
  static Camera framing(const Vec3& box_min_m, const Vec3& box_max_m, double aspect, const Vec3& from);
  /// A scene's camera: looking from `from` (as above) at the sphere of frame_radius_m around look_at_m, the sphere
  /// in view, when frame_radius_m > 0 (a part of the model: near and far then take in the whole box, so the rest of
  /// the model is drawn around it); otherwise framing(box_min_m, box_max_m, aspect, from).
  static Camera framing_part(const Vec3& box_min_m, const Vec3& box_max_m, double aspect, const Vec3& from,
                             const Vec3& look_at_m, double frame_radius_m);

  /// World-to-eye transform (OpenGL convention: eye looks down -z), 4x4, column-major like glLoadMatrixd.
  Eigen::Matrix4d view_matrix() const;
  /// Eye-to-clip perspective transform for the aspect (width / height), 4x4 like glFrustum.
  Eigen::Matrix4d projection_matrix(double aspect) const;
};

}  // namespace palpate
