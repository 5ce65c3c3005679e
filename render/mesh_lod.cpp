#include "render/mesh_lod.h"

#include <algorithm>
#include <cmath>

namespace palpate {
namespace {

using Tris = std::vector<std::array<int32_t, 3>>;

// window positions of every vertex (NaN where it cannot be placed)
std::vector<Eigen::Vector2d> project_all(const std::vector<Vec3>& v, const ProjectFn& project) {
  std::vector<Eigen::Vector2d> xy(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) xy[i] = project(v[i]);
  return xy;
}

double median_of(std::vector<double>* x) {
  if (x->empty()) return std::numeric_limits<double>::quiet_NaN();
  auto mid = x->begin() + static_cast<std::ptrdiff_t>(x->size() / 2);
  std::nth_element(x->begin(), mid, x->end());
  return *mid;
}

// Triangles a median is taken over at most: a model of more is sampled evenly (every k-th triangle), which a
// median of a million triangles' edges leaves within a fraction of a percent; on 15M triangles the whole set took
// 2.8 s of a recording's start-up.
constexpr std::size_t kMedianTriangles = std::size_t{1} << 20;

// median on-screen edge of the triangles; with m_per_px, also the median of world length over screen length
double median_edge(const std::vector<Vec3>& v, const std::vector<Eigen::Vector2d>& xy, const Tris& tris,
                   double* m_per_px) {
  const std::size_t stride = (tris.size() + kMedianTriangles - 1) / kMedianTriangles;
  std::vector<double> px, ratio;
  px.reserve(3 * (tris.size() / std::max<std::size_t>(stride, 1) + 1));
  if (m_per_px) ratio.reserve(px.capacity());
  for (std::size_t i = 0; i < tris.size(); i += std::max<std::size_t>(stride, 1)) {
    const auto& t = tris[i];
    for (int k = 0; k < 3; ++k) {
      const int32_t a = t[k], b = t[(k + 1) % 3];
      const double l = (xy[a] - xy[b]).norm();
      if (!std::isfinite(l)) continue;
      px.push_back(l);
      if (m_per_px && l > 1e-9) ratio.push_back((v[a] - v[b]).norm() / l);
    }
  }
  if (m_per_px) *m_per_px = median_of(&ratio);
  return median_of(&px);
}

// vertex clustering on a grid of cubes of edge cell_m: writes the triangles and each used vertex's
// representative (rep, n_v, -1 for unused vertices); false when the grid is too fine to index
bool cluster(const std::vector<Vec3>& v, const Tris& tris, const std::vector<uint8_t>& used, const Vec3& lo,
             double cell_m, std::vector<int32_t>* rep, Tris* out) {
  constexpr int64_t kAxis = int64_t{1} << 21;
  std::vector<std::pair<uint64_t, int32_t>> keyed;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!used[i]) continue;
    const Vec3 c = (v[i] - lo) / cell_m;
    if (!(c.maxCoeff() < static_cast<double>(kAxis - 1))) return false;
    const auto ix = static_cast<uint64_t>(std::max(0.0, std::floor(c.x())));
    const auto iy = static_cast<uint64_t>(std::max(0.0, std::floor(c.y())));
    const auto iz = static_cast<uint64_t>(std::max(0.0, std::floor(c.z())));
    keyed.emplace_back((ix << 42) | (iy << 21) | iz, static_cast<int32_t>(i));
  }
  std::sort(keyed.begin(), keyed.end());
  rep->assign(v.size(), -1);
  for (std::size_t b = 0; b < keyed.size();) {
    std::size_t e = b;
    Vec3 sum = Vec3::Zero();
    while (e < keyed.size() && keyed[e].first == keyed[b].first) sum += v[keyed[e++].second];
    // the member nearest the cluster's centroid stands for it (lowest index on a tie: the keys sort by it)
    const Vec3 centroid = sum / static_cast<double>(e - b);
    int32_t best = keyed[b].second;
    double best_d = (v[best] - centroid).squaredNorm();
    for (std::size_t k = b + 1; k < e; ++k) {
      const double d = (v[keyed[k].second] - centroid).squaredNorm();
      if (d < best_d) best = keyed[k].second, best_d = d;
    }
    for (std::size_t k = b; k < e; ++k) (*rep)[keyed[k].second] = best;
    b = e;
  }
  // remapped triangles that keep three distinct vertices, each unordered triple once (its first source)
  std::vector<std::array<int32_t, 4>> sorted;  // sorted triple, source index
  for (std::size_t t = 0; t < tris.size(); ++t) {
    std::array<int32_t, 3> r = {(*rep)[tris[t][0]], (*rep)[tris[t][1]], (*rep)[tris[t][2]]};
    if (r[0] == r[1] || r[1] == r[2] || r[0] == r[2]) continue;
    std::sort(r.begin(), r.end());
    sorted.push_back({r[0], r[1], r[2], static_cast<int32_t>(t)});
  }
  std::sort(sorted.begin(), sorted.end());
  std::vector<int32_t> first;
  for (std::size_t k = 0; k < sorted.size(); ++k)
    if (k == 0 || sorted[k][0] != sorted[k - 1][0] || sorted[k][1] != sorted[k - 1][1] ||
        sorted[k][2] != sorted[k - 1][2])
      first.push_back(sorted[k][3]);
  std::sort(first.begin(), first.end());
  out->clear();
  out->reserve(first.size());
  for (int32_t t : first) {
    const auto& s = tris[t];
    std::array<int32_t, 3> r = {(*rep)[s[0]], (*rep)[s[1]], (*rep)[s[2]]};
    // a cluster can fold a triangle over: it then faces away from its source, and two-sided lighting would
    // shade it as a back face (a dark speck on a lit surface); it takes its source's side
    const Vec3 n_src = (v[s[1]] - v[s[0]]).cross(v[s[2]] - v[s[0]]);
    const Vec3 n = (v[r[1]] - v[r[0]]).cross(v[r[2]] - v[r[0]]);
    if (n.dot(n_src) < 0.0) std::swap(r[1], r[2]);
    out->push_back(r);
  }
  return true;
}

}  // namespace

double median_edge_px(const std::vector<Vec3>& vertices_m, const Tris& triangles, const ProjectFn& project) {
  return median_edge(vertices_m, project_all(vertices_m, project), triangles, nullptr);
}

std::optional<MeshLod> screen_lod(const std::vector<Vec3>& vertices_m, const Tris& triangles,
                                  const ProjectFn& project, double min_edge_px) {
  if (!(min_edge_px > 0.0) || triangles.empty()) return std::nullopt;
  const std::vector<Eigen::Vector2d> xy = project_all(vertices_m, project);
  double m_per_px = 0.0;
  const double median_px = median_edge(vertices_m, xy, triangles, &m_per_px);
  if (!(median_px < min_edge_px) || !(m_per_px > 0.0) || !std::isfinite(m_per_px)) return std::nullopt;

  std::vector<uint8_t> used(vertices_m.size(), 0);
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  for (const auto& t : triangles)
    for (int32_t i : t) {
      used[i] = 1;
      lo = lo.cwiseMin(vertices_m[i]);
    }
  if (!lo.allFinite()) return std::nullopt;

  // a cube of one target edge gives a median edge between neighbouring clusters of about a cube, a little short
  // of the target on the bunny (0.98 px for 1 px): the median is measured and the cube grown until it is within
  // 5 % of the target (at most four passes)
  MeshLod lod;
  lod.median_edge_px = median_px;
  std::vector<int32_t> rep;
  double cell_m = min_edge_px * m_per_px;
  for (int pass = 0; pass < 4; ++pass) {
    if (!cluster(vertices_m, triangles, used, lo, cell_m, &rep, &lod.triangles)) return std::nullopt;
    lod.cell_m = cell_m;
    lod.lod_median_edge_px = median_edge(vertices_m, xy, lod.triangles, nullptr);
    if (!(lod.lod_median_edge_px < 0.95 * min_edge_px)) break;
    cell_m *= std::clamp(min_edge_px / lod.lod_median_edge_px, 1.1, 4.0);
  }
  if (lod.triangles.empty()) return std::nullopt;

  std::vector<uint8_t> is_rep(vertices_m.size(), 0);
  for (std::size_t i = 0; i < vertices_m.size(); ++i) {
    if (rep[i] < 0) continue;
    is_rep[rep[i]] = 1;
    lod.max_shift_m = std::max(lod.max_shift_m, (vertices_m[i] - vertices_m[rep[i]]).norm());
    const double px = (xy[i] - xy[rep[i]]).norm();
    if (std::isfinite(px)) lod.max_shift_px = std::max(lod.max_shift_px, px);
  }
  // count each vertex the triangles use once (2: counted)
  for (const auto& t : lod.triangles)
    for (int32_t i : t)
      if (is_rep[i] == 1) {
        ++lod.representatives;
        is_rep[i] = 2;
      }
  return lod;
}

}  // namespace palpate
