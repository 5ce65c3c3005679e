#include "sim/cut/cut_incision.h"

#include <algorithm>
#include <cmath>

namespace palpate {
namespace {

// the swept surface's unit normal from the quad's diagonals; zero when the blade hardly moved
Vec3 swept_normal(const BladeQuad& quad) {
  const Vec3 n = (quad.end1_m - quad.tip0_m).cross(quad.end0_m - quad.tip1_m);
  const double span2 = std::max((quad.end1_m - quad.tip0_m).squaredNorm(), (quad.end0_m - quad.tip1_m).squaredNorm());
  return n.squaredNorm() > 1e-18 * span2 * span2 ? Vec3(n.normalized()) : Vec3(Vec3::Zero());
}

// at + off, off halved while keep refuses the point (three times at most), else at itself
Vec3 kept(const Vec3& at, Vec3 off, const IncisionShape& shape) {
  for (int i = 0; i < 3 && shape.keep && !shape.keep(at + off); ++i) off *= 0.5;
  if (shape.keep && !shape.keep(at + off)) return at;
  return at + off;
}

}  // namespace

Vec3 incision_point(const BladeQuad& quad, const Vec3& crossing_m, const Vec3& surface_normal, double edge_m,
                    const IncisionShape& shape) {
  if (!(shape.depth_m > 0.0)) return crossing_m;
  // the swept surface's normal (a quad whose blade hardly moved has none)
  const Vec3 across = swept_normal(quad);
  if (across.isZero() || !surface_normal.allFinite()) return crossing_m;

  // into the material along the swept surface and across the sweep: the surface's inward normal without its parts
  // across the blade and along the blade's motion (a face the blade's edge runs into head on, at a stroke's ends,
  // is not grooved: sunk along the motion, its copies would lie in the blade's path ahead and be cut again),
  // shallower as the blade meets the surface at a grazing angle (none below 30 degrees)
  Vec3 in = -surface_normal + surface_normal.dot(across) * across;
  const Vec3 motion = across.cross(quad.end0_m - quad.tip0_m + quad.end1_m - quad.tip1_m).normalized();
  if (motion.allFinite()) in -= in.dot(motion) * motion;
  const double steep = in.norm();
  double depth = std::min(shape.depth_m, edge_m) * std::clamp(2.0 * steep - 1.0, 0.0, 1.0);
  if (depth > 0.0) {
    in /= steep;
    // never past the blade's tip where the tip is ahead (inside); where the blade left through this surface its
    // tip is behind and the groove takes its whole depth
    const Vec3 tip = quad.tip1_m - quad.tip0_m;
    const double s = tip.squaredNorm() > 0.0 ? std::clamp((crossing_m - quad.tip0_m).dot(tip) / tip.squaredNorm(), 0.0, 1.0) : 0.0;
    const double ahead_m = (quad.tip0_m + s * tip - crossing_m).dot(in);
    if (ahead_m > 0.0) depth = std::min(depth, ahead_m);
  }
  // back toward the crossing while the point is refused (a thin part sunk through into a cell outside the lattice)
  return kept(crossing_m, depth * in, shape);
}

Vec3 incision_side_point(const BladeQuad& quad, const Vec3& at, const Vec3& toward_m, const IncisionShape& shape) {
  const Vec3 n = swept_normal(quad);
  if (!(shape.gap_m > 0.0) || n.isZero()) return at;
  return kept(at, (n.dot(toward_m) >= 0.0 ? 0.5 : -0.5) * shape.gap_m * n, shape);
}

}  // namespace palpate
