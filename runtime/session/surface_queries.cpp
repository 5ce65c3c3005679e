#include "runtime/session/surface_queries.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "haptics/force/triangle_queries.h"

namespace palpate {
namespace {

Vec3 face_normal(const TriMesh& mesh, int32_t t) {
  const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
  const Vec3 n = (mesh.vertices_m[tri[1]] - mesh.vertices_m[tri[0]]).cross(mesh.vertices_m[tri[2]] - mesh.vertices_m[tri[0]]);
  const double len = n.norm();
  return len > 0.0 ? Vec3(n / len) : Vec3::UnitZ();
}

// nearest of the given triangles to p (distance +inf when the list is empty)
SurfaceHit nearest_of(const TriMesh& mesh, const std::vector<int32_t>& ids, const Vec3& p) {
  SurfaceHit best;
  best.distance_m = std::numeric_limits<double>::infinity();
  for (int32_t t : ids) {
    const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
    Vec3 bary;
    const Vec3 q = closest_point_on_triangle(p, mesh.vertices_m[tri[0]], mesh.vertices_m[tri[1]], mesh.vertices_m[tri[2]],
                                             &bary);
    const double d = (q - p).norm();
    if (d < best.distance_m) {
      best.distance_m = d;
      best.point_m = q;
      best.triangle = t;
    }
  }
  return best;
}

// whether segment p0 -> p1 crosses triangle t of mesh from its front (the servo's entry test), or, with either_side,
// from its back too; *u: where along the segment
bool segment_crosses(const TriMesh& mesh, int32_t t, const Vec3& p0, const Vec3& p1, bool either_side, double* u) {
  const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
  const Vec3& a = mesh.vertices_m[tri[0]];
  const Vec3& b = mesh.vertices_m[tri[1]];
  const Vec3& c = mesh.vertices_m[tri[2]];
  Vec3 bary;
  return segment_enters_triangle(p0, p1, a, b, c, u, &bary) ||
         (either_side && segment_enters_triangle(p0, p1, a, c, b, u, &bary));
}

}  // namespace

std::optional<SurfaceHit> first_ray_hit(const Model& model, const Vec3& origin_m, const Vec3& dir, double length_m,
                                        bool front_only) {
  const double n = dir.norm();
  if (!(n > 0.0) || !(length_m > 0.0) || !origin_m.allFinite()) return std::nullopt;
  const Vec3 end = origin_m + dir * (length_m / n);
  // candidates: the leaves the segment's box touches (a superset of those it crosses)
  std::vector<int32_t> ids;
  model.grid.triangles_near(origin_m.cwiseMin(end), origin_m.cwiseMax(end), &ids);
  const TriMesh& mesh = model.rest;
  std::optional<SurfaceHit> best;
  double best_u = 2.0;
  for (int32_t t : ids) {
    double u = 0.0;
    if (!segment_crosses(mesh, t, origin_m, end, !front_only, &u) || u >= best_u) continue;
    best_u = u;
    SurfaceHit h;
    h.point_m = origin_m + u * (end - origin_m);
    h.normal = face_normal(mesh, t);
    h.triangle = t;
    h.distance_m = u * length_m;
    best = h;
  }
  return best;
}

std::optional<SurfaceHit> nearest_surface_point(const Model& model, const Vec3& p_m) {
  const TriMesh& mesh = model.rest;
  if (mesh.triangles.empty() || !p_m.allFinite()) return std::nullopt;
  const Aabb& cube = model.normalization.cube;
  // grow a box around p until it holds a triangle: the nearest of those bounds the true distance ...
  const double gap_m = (p_m - p_m.cwiseMax(cube.min_m).cwiseMin(cube.max_m)).norm();
  double r = gap_m + std::max(model.leaf_cell_m, 1e-9);
  std::vector<int32_t> ids;
  const double side_m = cube.extent().maxCoeff();
  for (;;) {
    model.grid.triangles_near(p_m - Vec3::Constant(r), p_m + Vec3::Constant(r), &ids);
    if (!ids.empty() || r > gap_m + 2.0 * side_m) break;
    r *= 2.0;
  }
  SurfaceHit best = nearest_of(mesh, ids, p_m);
  if (!std::isfinite(best.distance_m)) return std::nullopt;
  // ... and every triangle within that distance lies in the box of that half-side
  model.grid.triangles_near(p_m - Vec3::Constant(best.distance_m), p_m + Vec3::Constant(best.distance_m), &ids);
  const SurfaceHit exact = nearest_of(mesh, ids, p_m);
  if (exact.distance_m < best.distance_m) best = exact;
  best.normal = face_normal(mesh, best.triangle);
  return best;
}

double proven_depth_inside(const Model& model, const Vec3& p_m, double reach_m) {
  const GridHierarchy& g = model.grid;
  const int level = g.levels();
  const double leaf = g.cell_size_m(level);
  constexpr int kMaxLayers = 24;
  const double wanted = std::ceil(std::max(reach_m, 0.0) / leaf) + 1.0;
  if (!g.cube().contains(p_m) || !(wanted <= kMaxLayers)) return 0.0;
  const int layers = static_cast<int>(wanted), n = g.cells_per_axis(level);
  const CellCoord c = g.cell_of(p_m, level);
  auto inside = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= n || j >= n || k >= n) return false;
    const int32_t id = g.linear_index({i, j, k}, level);
    return g.solid_cell(id, level) && !g.surface_cell(id, level);
  };
  if (!inside(c.i, c.j, c.k)) return 0.0;  // the usual case (a free tool outside), decided by one cell
  for (int k = c.k - layers; k <= c.k + layers; ++k)
    for (int j = c.j - layers; j <= c.j + layers; ++j)
      for (int i = c.i - layers; i <= c.i + layers; ++i)
        if (!inside(i, j, k)) return 0.0;
  return layers * leaf;
}

namespace {

// whether the ray from p along dir to the cube's border crosses the rest surface an odd number of times
bool odd_crossings(const Model& model, const Vec3& p, const Vec3& dir) {
  const Aabb& cube = model.normalization.cube;
  const Vec3 end = p + dir * (2.0 * cube.extent().norm());
  std::vector<int32_t> ids;
  model.grid.triangles_near(p.cwiseMin(end), p.cwiseMax(end), &ids);
  const TriMesh& mesh = model.rest;
  int crossings = 0;
  for (int32_t t : ids) {
    double u = 0.0;
    crossings += segment_crosses(mesh, t, p, end, true, &u);
  }
  return crossings % 2 == 1;
}

}  // namespace

namespace {

// whether segment p0 -> p1 passes from one side of triangle t's plane to the other inside it, by the half-open rule
// (a point on the plane is behind it, so a path that stops on the plane and goes on is counted once); *u: where along
// the segment
bool passes_through(const TriMesh& mesh, int32_t t, const Vec3& p0, const Vec3& p1, double* u) {
  const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
  const Vec3& a = mesh.vertices_m[tri[0]];
  const Vec3 e1 = mesh.vertices_m[tri[1]] - a, e2 = mesh.vertices_m[tri[2]] - a;
  const Vec3 n = e1.cross(e2);
  const double d0 = (p0 - a).dot(n), d1 = (p1 - a).dot(n);
  if ((d0 > 0.0) == (d1 > 0.0)) return false;
  const double s = d0 / (d0 - d1);
  const Vec3 x = p0 + s * (p1 - p0) - a;
  // x's barycentric coordinates in the triangle (its edges inclusive)
  const double nn = n.squaredNorm();
  if (!(nn > 0.0)) return false;
  const double v = x.cross(e2).dot(n) / nn, w = e1.cross(x).dot(n) / nn;
  if (v < 0.0 || w < 0.0 || v + w > 1.0) return false;
  *u = s;
  return true;
}

}  // namespace

int path_crossings(const Model& model, const Vec3& p0_m, const Vec3& p1_m, std::vector<int32_t>* ids) {
  if (!p0_m.allFinite() || !p1_m.allFinite() || p0_m == p1_m) return 0;
  model.grid.triangles_near(p0_m.cwiseMin(p1_m), p0_m.cwiseMax(p1_m), ids);
  // where along the segment each crossing is; a segment through an edge or a corner meets every face at it there
  double at[8];
  int n = 0, extra = 0;
  for (int32_t t : *ids) {
    double u = 0.0;
    if (!passes_through(model.rest, t, p0_m, p1_m, &u)) continue;
    bool same = false;
    for (int i = 0; i < n && !same; ++i) same = std::abs(at[i] - u) <= 1e-9;
    if (same) continue;
    if (n < 8) at[n++] = u;
    else ++extra;  // (more than eight places in a tick's path: counted without the merge)
  }
  return n + extra;
}

double depth_inside(const Model& model, const Vec3& p_m, double reach_m, double* still_m) {
  const GridHierarchy& g = model.grid;
  const int level = g.levels();
  double unused = 0.0;
  double& still = still_m ? *still_m : unused;
  still = 0.0;
  if (!model.closed || !p_m.allFinite() || !g.cube().contains(p_m)) return 0.0;
  const int32_t id = g.linear_index(g.cell_of(p_m, level), level);
  if (!g.solid_cell(id, level)) return 0.0;  // the usual case (a free tool outside), decided by one cell
  const auto hit = nearest_surface_point(model, p_m);
  if (!hit) return 0.0;
  // within reach of the surface, inside or out: it stays so while it moves less than the rest of the reach
  if (!(hit->distance_m > reach_m)) {
    still = reach_m - hit->distance_m;
    return 0.0;
  }
  if (!g.surface_cell(id, level)) return hit->distance_m;  // enclosed by the surface
  if ((p_m - hit->point_m).dot(hit->normal) >= 0.0) return 0.0;
  // the rays slightly off the axes, so that none runs along a face or through an edge of an axis-aligned model
  const Vec3 dirs[3] = {Vec3(1.0, 0.0123, 0.0071).normalized(), Vec3(0.0089, 1.0, 0.0137).normalized(),
                        Vec3(0.0113, 0.0067, 1.0).normalized()};
  int odd = 0;
  for (const Vec3& d : dirs) odd += odd_crossings(model, p_m, d);
  return odd >= 2 ? hit->distance_m : 0.0;
}

}  // namespace palpate
