#include "tools/commands/scene_target.h"

#include <algorithm>
#include <utility>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <vector>

#include "haptics/servo/local_model.h"

namespace palpate {

char guess_up_axis(const Aabb& raw_box, const std::string& path, std::string* why) {
  const Vec3 e = raw_box.extent();
  int thin = 0;
  e.minCoeff(&thin);
  Vec3 sorted = e;
  std::sort(sorted.data(), sorted.data() + 3);
  if (sorted[0] < 0.35 * sorted[1]) {
    *why = std::string("the model is flat across ") + static_cast<char>('x' + thin);
    return static_cast<char>('x' + thin);
  }
  int standing = -1, count = 0;
  for (int a = 0; a < 3; ++a) {
    const double tol = 0.02 * e.maxCoeff();
    const bool on_zero = std::abs(raw_box.min_m[a]) <= tol && raw_box.max_m[a] > tol;
    bool others_straddle = true;
    for (int b = 0; b < 3; ++b)
      if (b != a && !(raw_box.min_m[b] < -tol && raw_box.max_m[b] > tol)) others_straddle = false;
    if (on_zero && others_straddle) {
      standing = a;
      ++count;
    }
  }
  if (count == 1) {
    *why = std::string("the model stands on ") + static_cast<char>('x' + standing) + " = 0";
    return static_cast<char>('x' + standing);
  }
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* z_up : {".stl", ".3ds", ".blend", ".3mf", ".amf", ".dxf", ".ifc", ".off"})
    if (ext == z_up) {
      *why = "the custom of " + ext + " files";
      return 'z';
    }
  *why = "the custom of " + (ext.empty() ? std::string("most formats") : ext + " files");
  return 'y';
}

bool feelable(const Model& model, const SurfaceHit& hit, double grab_radius_m) {
  const double margin_m = std::max(2.0 * model.leaf_cell_m, grab_radius_m);  // as FrameStage::publish_patch
  std::vector<int32_t> ids;
  model.grid.triangles_near(hit.point_m - Vec3::Constant(margin_m), hit.point_m + Vec3::Constant(margin_m), &ids);
  if (ids.size() <= static_cast<std::size_t>(LocalModel::kMaxTriangles)) return true;
  auto centroid_d2 = [&](int32_t t) {
    const auto& tri = model.rest.triangles[static_cast<std::size_t>(t)];
    const Vec3 c = (model.rest.vertices_m[tri[0]] + model.rest.vertices_m[tri[1]] + model.rest.vertices_m[tri[2]]) / 3.0;
    return (c - hit.point_m).squaredNorm();
  };
  const double mine = centroid_d2(hit.triangle);
  std::size_t closer = 0;
  for (int32_t t : ids) closer += centroid_d2(t) < mine ? 1 : 0;
  return closer + 1 < static_cast<std::size_t>(LocalModel::kMaxTriangles);
}

std::optional<SurfaceHit> surface_from(const Model& model, const Aabb& box, const Vec3& from, double grab_radius_m,
                                       bool* offset, std::vector<SurfaceHit>* more) {
  const double reach_m = box.extent().norm() + 0.05;
  const Vec3 u = from.unitOrthogonal();
  const Vec3 v = from.cross(u);
  const TriMesh& mesh = model.rest;
  // a hit the hand finds: facing the tool, not grazed, met alike by rays a little beside it (inside its face)
  auto steady = [&](const Vec3& through, const SurfaceHit& hit) {
    if (hit.normal.dot(from) < 0.3) return false;
    const auto& t = mesh.triangles[static_cast<std::size_t>(hit.triangle)];
    const Vec3 &a = mesh.vertices_m[t[0]], &b = mesh.vertices_m[t[1]], &c = mesh.vertices_m[t[2]];
    const double twice_area_m2 = (b - a).cross(c - a).norm();
    const double inradius_m = twice_area_m2 / ((b - a).norm() + (c - b).norm() + (a - c).norm());
    const double side_m = std::min(3e-4, 0.5 * inradius_m);
    // inside its triangle, off its edges: a tool moving exactly along the edge two triangles share (the diagonal
    // of a CAD model's square face, through its centre) can slip between them and a blade never meet the surface
    for (const auto& [p, q] : {std::pair{&a, &b}, std::pair{&b, &c}, std::pair{&c, &a}}) {
      const double edge_m = (*q - *p).norm();
      const double to_edge_m = edge_m > 0.0 ? (*q - *p).cross(hit.point_m - *p).norm() / edge_m : 0.0;
      if (to_edge_m < std::min(5e-4, 0.25 * inradius_m)) return false;
    }
    for (const Vec3& dir : {u, Vec3(-u), v, Vec3(-v)}) {
      const auto h = first_ray_hit(model, through + side_m * dir + reach_m * from, -from, 2.0 * reach_m, true);
      if (!h || std::abs(h->distance_m - hit.distance_m) > 1e-3) return false;
    }
    return true;
  };
  auto try_through = [&](const Vec3& through) -> std::optional<SurfaceHit> {
    const auto hit = first_ray_hit(model, through + reach_m * from, -from, 2.0 * reach_m, true);
    if (hit && steady(through, *hit) && feelable(model, *hit, grab_radius_m)) return hit;
    return std::nullopt;
  };
  // the outermost ring stays inside the box: a ray along its border grazes the model
  const double step_u_m = u.cwiseAbs().dot(box.extent()) / 18.0;
  const double step_v_m = v.cwiseAbs().dot(box.extent()) / 18.0;
  std::optional<SurfaceHit> first;
  for (int ring = 0; ring <= 8; ++ring)
    for (int i = -ring; i <= ring; ++i)
      for (int j = -ring; j <= ring; ++j) {
        if (std::max(std::abs(i), std::abs(j)) != ring) continue;
        auto hit = try_through(box.center() + i * step_u_m * u + j * step_v_m * v);
        if (!hit) continue;
        if (!first) {
          first = hit;
          *offset = ring > 0;
        } else {
          more->push_back(*hit);
        }
        if (!more || more->size() >= kMoreSurfacePoints) return first;
      }
  if (first) return first;
  std::vector<std::pair<double, Vec3>> centroids;
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = mesh.vertices_m[t[0]], &b = mesh.vertices_m[t[1]], &c = mesh.vertices_m[t[2]];
    if ((b - a).cross(c - a).dot(from) <= 0.0) continue;
    const Vec3 m = (a + b + c) / 3.0;
    const Vec3 off = (m - box.center()) - (m - box.center()).dot(from) * from;
    centroids.emplace_back(off.squaredNorm(), m);
  }
  const std::size_t tries = std::min<std::size_t>(centroids.size(), 256);
  std::partial_sort(centroids.begin(), centroids.begin() + static_cast<std::ptrdiff_t>(tries), centroids.end(),
                    [](const auto& x, const auto& y) { return x.first < y.first; });
  for (std::size_t i = 0; i < tries; ++i)
    if (auto hit = try_through(centroids[i].second)) {
      *offset = true;
      return hit;
    }
  return std::nullopt;
}

}  // namespace palpate
