// The touch servo's queries of the patch: the nearest surface point, a material point, whether a touch begins and on
// which side, whether the tool is outside. Part of the servo (haptics/servo/servo.h). Thread: servo.
#include <cmath>

#include "haptics/force/triangle_queries.h"
#include "haptics/servo/servo.h"
#include "haptics/servo/servo_touch_limits.h"

namespace palpate {

using servo_touch::kReturnReach_m;

bool Servo::closest_on_patch(const LocalModel& m, const Vec3& p, int* slot, Vec3* point, Vec3* bary,
                             const Vec3* side, double min_cos) const noexcept {
  double best = INFINITY;
  for (int i = 0; i < m.num_triangles; ++i) {
    Vec3 b = Vec3::Zero();
    const auto& t = m.tri_m[i];
    if (side) {
      const Vec3 face = (t[1] - t[0]).cross(t[2] - t[0]);
      if (face.dot(*side) <= min_cos * face.norm()) continue;
    }
    const Vec3 q = closest_point_on_triangle(p, t[0], t[1], t[2], &b);
    const double d = (q - p).squaredNorm();
    if (d < best) {
      best = d;
      *slot = i;
      *point = q;
      *bary = b;
    }
  }
  return best < INFINITY;
}

bool Servo::material_point(const LocalModel& m, int32_t tri, const Vec3& bary, Vec3* point) noexcept {
  for (int i = 0; i < m.num_triangles; ++i)
    if (m.tri_ids[i] == tri) {
      const auto& t = m.tri_m[i];
      *point = bary[0] * t[0] + bary[1] * t[1] + bary[2] * t[2];
      return true;
    }
  return false;
}

void Servo::track_nearest(const LocalModel& m, const Vec3& tool, double r) noexcept {
  int slot = -1;
  Vec3 b = Vec3::Zero();
  near_tri_ = closest_on_patch(m, tool, &slot, &near_m_, &b) ? m.tri_ids[slot] : -1;
  near_bary_ = b;
  Vec3 normal = Vec3::Zero();
  near_outside_ = near_tri_ >= 0 && (tool - near_m_).norm() <= r + kReturnReach_m &&
                  outside_of(m, slot, b, near_m_, tool, r, &normal) && normal.squaredNorm() > 0.0;
  if (near_outside_) near_normal_ = normal.normalized();
}

bool Servo::touch_begins(const LocalModel& m, const Vec3& from, const Vec3& tool, double r, bool* back,
                         int* slot) noexcept {
  // the tool's path from `from` enters a face from its front (a fast tool), or a sphere's centre comes within its
  // radius of a face while in front of its plane; on a two-sided surface (not closed: no inside), from its back too,
  // when no face is met from its front (a sphere over a convex edge is behind the plane of the face beyond the edge,
  // and within its radius of that face's edge: its front is met first, and taken)
  *back = false;
  for (const bool behind : {false, true}) {
    if (behind && !m.two_sided) break;
    for (int i = 0; i < m.num_triangles; ++i) {
      const auto& t = m.tri_m[i];
      const Vec3 front = (t[1] - t[0]).cross(t[2] - t[0]);
      const Vec3 face = behind ? Vec3(-front) : front;
      double u = 0.0;
      Vec3 b = Vec3::Zero();
      bool begins = behind ? segment_enters_triangle(from, tool, t[0], t[2], t[1], &u, &b)
                           : segment_enters_triangle(from, tool, t[0], t[1], t[2], &u, &b);
      if (!begins && params_.tool_radius_m > 0.0) {
        const Vec3 q = closest_point_on_triangle(tool, t[0], t[1], t[2], &b);
        begins = (tool - q).squaredNorm() < r * r && (tool - q).dot(face) > 0.0;
      }
      if (begins) {
        contact_normal_ = face.normalized();
        *back = behind;
        *slot = i;
        return true;
      }
    }
  }
  return false;
}

bool Servo::outside_of(const LocalModel& m, int slot, const Vec3& b, const Vec3& q, const Vec3& tool, double r,
                       Vec3* normal_out) const noexcept {
  // in front of the surface point q's smooth normal (on the contact's side), and a radius from it
  const auto& n = m.normal[slot];
  const Vec3 smooth = b[0] * n[0] + b[1] * n[1] + b[2] * n[2];
  const Vec3 normal = smooth.squaredNorm() > 0.0 ? smooth : contact_normal_;
  if (normal_out) *normal_out = normal;
  const Vec3 d = tool - q;
  return d.dot(normal) > 0.0 && d.squaredNorm() >= r * r * (1.0 - 1e-6);
}

bool Servo::tool_outside(const LocalModel& m, const Vec3& tool, double r) const noexcept {
  int slot = -1;
  Vec3 q = Vec3::Zero(), b = Vec3::Zero();
  if (!closest_on_patch(m, tool, &slot, &q, &b, &contact_normal_)) return true;
  return outside_of(m, slot, b, q, tool, r, nullptr);
}

}  // namespace palpate
