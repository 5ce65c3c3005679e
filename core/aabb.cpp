#include "core/aabb.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace palpate {

namespace {

std::string fmt_g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

}  // namespace

Vec3 Aabb::extent() const { return max_m - min_m; }

Vec3 Aabb::center() const { return 0.5 * (min_m + max_m); }

bool Aabb::contains(const Vec3& p) const {
  return (p.array() >= min_m.array()).all() && (p.array() <= max_m.array()).all();
}

Aabb Aabb::of(const std::vector<Vec3>& points) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Aabb box{Vec3::Constant(kInf), Vec3::Constant(-kInf)};
  for (const Vec3& p : points) {
    box.min_m = box.min_m.cwiseMin(p);
    box.max_m = box.max_m.cwiseMax(p);
  }
  return box;
}

Result<Normalization> normalize_mesh(TriMesh* mesh, double size_m, const std::string& name) {
  const std::string who = "mesh '" + name + "': ";
  if (!std::isfinite(size_m) || size_m <= 0.0) {
    return make_error(who, "size ", fmt_g(size_m), " is not a positive finite number");
  }
  const std::size_t nv = mesh->vertices_m.size();
  if (nv == 0) return make_error(who, "no vertices");
  if (mesh->triangles.empty()) return make_error(who, "no triangles");
  for (std::size_t t = 0; t < mesh->triangles.size(); ++t) {
    for (int32_t v : mesh->triangles[t]) {
      if (v < 0 || static_cast<std::size_t>(v) >= nv) {
        return make_error(who, "triangle ", std::to_string(t), " vertex index ", std::to_string(v),
                          " is beyond the vertex list (size ", std::to_string(nv), ")");
      }
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    if (!mesh->vertices_m[v].allFinite()) return make_error(who, "vertex ", std::to_string(v), " is not finite");
  }

  const Aabb raw = Aabb::of(mesh->vertices_m);
  const Vec3 extent = raw.extent();
  int largest_axis = 0;
  const double largest = extent.maxCoeff(&largest_axis);
  // a largest extent lost in rounding of the coordinates counts as a single point
  const double magnitude = std::max(raw.min_m.cwiseAbs().maxCoeff(), raw.max_m.cwiseAbs().maxCoeff());
  if (!(largest > 1e-12 * magnitude)) return make_error(who, "all vertices at one point");
  static const char* const kAxis[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    if (extent[a] < 1e-6 * largest) {
      return make_error(who, "flat on axis ", kAxis[a], " (extent ", fmt_g(extent[a]), " of ", fmt_g(largest),
                        ")");
    }
  }

  Normalization norm;
  norm.scale = size_m / largest;
  const Vec3 center = raw.center();
  norm.offset_m = -norm.scale * center;
  const double half_m = 0.5 * size_m;
  norm.cube = Aabb{Vec3::Constant(-half_m), Vec3::Constant(half_m)};
  for (Vec3& v : mesh->vertices_m) {
    const Vec3 raw_v = v;
    v = ((raw_v - center) * norm.scale).cwiseMax(norm.cube.min_m).cwiseMin(norm.cube.max_m);
    // the extreme points on the largest axis land exactly on the cube faces, so the extent is exactly size_m
    if (raw_v[largest_axis] == raw.min_m[largest_axis]) v[largest_axis] = -half_m;
    if (raw_v[largest_axis] == raw.max_m[largest_axis]) v[largest_axis] = half_m;
  }
  return norm;
}

}  // namespace palpate
