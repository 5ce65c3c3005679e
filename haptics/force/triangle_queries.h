#pragma once
/// Point and segment queries against single triangles (used by the servo; noexcept, no allocation).

#include "core/types.h"

namespace palpate {

/// Closest point on triangle (a, b, c) to p; *bary receives its barycentric coordinates.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Vec3* bary) noexcept;

/// Whether segment p0->p1 crosses triangle (a, b, c) entering from its front (counter-clockwise) side;
/// on a hit *u receives the segment parameter in [0, 1] and *bary the barycentric coordinates.
bool segment_enters_triangle(const Vec3& p0, const Vec3& p1, const Vec3& a, const Vec3& b, const Vec3& c, double* u,
                             Vec3* bary) noexcept;

}  // namespace palpate
