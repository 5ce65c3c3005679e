#include "sim/triangle_grid.h"

#include <algorithm>
#include <cmath>

namespace palpate {

TriangleGrid::TriangleGrid(double cube_m, const std::vector<Vec3>& rest_m,
                           const std::vector<std::array<int32_t, 3>>& triangles)
    : cube_m_(cube_m) {
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    add(static_cast<int32_t>(t), rest_m[tri[0]], rest_m[tri[1]], rest_m[tri[2]]);
  }
}

std::array<int64_t, 3> TriangleGrid::cube_of(const Vec3& p_m) const {
  std::array<int64_t, 3> c{};
  for (int a = 0; a < 3; ++a) c[a] = static_cast<int64_t>(std::floor(p_m[a] / cube_m_));
  return c;
}

uint64_t TriangleGrid::key(const std::array<int64_t, 3>& c) {
  // 21 bits an axis, offset so negative cubes pack too
  constexpr int64_t kOff = int64_t{1} << 20;
  auto part = [](int64_t v) { return static_cast<uint64_t>((v + kOff) & ((int64_t{1} << 21) - 1)); };
  return part(c[0]) | (part(c[1]) << 21) | (part(c[2]) << 42);
}

void TriangleGrid::add(int32_t t, const Vec3& a_m, const Vec3& b_m, const Vec3& c_m) {
  const auto lo = cube_of(a_m.cwiseMin(b_m).cwiseMin(c_m)), hi = cube_of(a_m.cwiseMax(b_m).cwiseMax(c_m));
  for (int64_t k = lo[2]; k <= hi[2]; ++k)
    for (int64_t j = lo[1]; j <= hi[1]; ++j)
      for (int64_t i = lo[0]; i <= hi[0]; ++i) cubes_[key({i, j, k})].push_back(t);
}

void TriangleGrid::query(const Vec3& lo_m, const Vec3& hi_m, std::vector<int32_t>* out) const {
  if (!lo_m.allFinite() || !hi_m.allFinite()) return;
  const auto lo = cube_of(lo_m), hi = cube_of(hi_m);
  double span = 1.0;
  for (int a = 0; a < 3; ++a) span *= static_cast<double>(hi[a] - lo[a] + 1);
  if (span > static_cast<double>(cubes_.size())) {
    // a box over more cubes than are filled: visit the filled ones, in key order so the result is deterministic
    std::vector<uint64_t> keys;
    for (const auto& [k, ids] : cubes_) {
      std::array<int64_t, 3> c{};
      for (int a = 0; a < 3; ++a) c[a] = static_cast<int64_t>((k >> (21 * a)) & ((uint64_t{1} << 21) - 1)) - (int64_t{1} << 20);
      if (c[0] >= lo[0] && c[0] <= hi[0] && c[1] >= lo[1] && c[1] <= hi[1] && c[2] >= lo[2] && c[2] <= hi[2]) keys.push_back(k);
    }
    std::sort(keys.begin(), keys.end());
    for (uint64_t k : keys) {
      const auto& ids = cubes_.at(k);
      out->insert(out->end(), ids.begin(), ids.end());
    }
    return;
  }
  for (int64_t k = lo[2]; k <= hi[2]; ++k)
    for (int64_t j = lo[1]; j <= hi[1]; ++j)
      for (int64_t i = lo[0]; i <= hi[0]; ++i) {
        const auto it = cubes_.find(key({i, j, k}));
        if (it != cubes_.end()) out->insert(out->end(), it->second.begin(), it->second.end());
      }
}

}  // namespace palpate
