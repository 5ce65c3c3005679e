#include "haptics/force/triangle_queries.h"

#include <cmath>

namespace palpate {

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Vec3* bary) noexcept {
  // region tests on the triangle's Voronoi regions (vertices, edges, face)
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) { *bary = Vec3(1, 0, 0); return a; }
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) { *bary = Vec3(0, 1, 0); return b; }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    *bary = Vec3(1 - v, v, 0);
    return a + v * ab;
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) { *bary = Vec3(0, 0, 1); return c; }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    *bary = Vec3(1 - w, 0, w);
    return a + w * ac;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    *bary = Vec3(0, 1 - w, w);
    return b + w * (c - b);
  }
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) { *bary = Vec3(1, 0, 0); return a; }  // degenerate triangle
  const double v = vb / sum, w = vc / sum;
  *bary = Vec3(1 - v - w, v, w);
  return a + v * ab + w * ac;
}

bool segment_enters_triangle(const Vec3& p0, const Vec3& p1, const Vec3& a, const Vec3& b, const Vec3& c, double* u,
                             Vec3* bary) noexcept {
  const Vec3 dir = p1 - p0;
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 n = e1.cross(e2);
  const double den = -dir.dot(n);  // > 0 when moving against the normal (entering)
  if (!(den > 0.0)) return false;
  const Vec3 ap = p0 - a;
  const double t = ap.dot(n) / den;
  if (t < 0.0 || t > 1.0) return false;
  const Vec3 e = dir.cross(ap);
  const double v = -e2.dot(e) / den;
  const double w = e1.dot(e) / den;
  if (v < 0.0 || w < 0.0 || v + w > 1.0) return false;
  *u = t;
  *bary = Vec3(1 - v - w, v, w);
  return true;
}

}  // namespace palpate
