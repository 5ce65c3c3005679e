#include "sim/cut/triangle_grid.h"

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
  // clamped inside the key's 21 bits an axis
  for (int a = 0; a < 3; ++a) c[a] = static_cast<int64_t>(std::clamp(std::floor(p_m[a] / cube_m_), -1e6, 1e6));
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

void TriangleGrid::cube_keys(const Vec3& lo_m, const Vec3& hi_m, std::vector<uint64_t>* keys) const {
  if (!lo_m.allFinite() || !hi_m.allFinite()) return;
  const auto lo = cube_of(lo_m);
  auto hi = cube_of(hi_m);
  // a blade piece mapped to rest spans a few cubes (CutModel drops those that jumped); a box beyond 256 a side is
  // clamped so a stray one cannot stall the frame
  for (int a = 0; a < 3; ++a) hi[a] = std::min(hi[a], lo[a] + 255);
  for (int64_t k = lo[2]; k <= hi[2]; ++k)
    for (int64_t j = lo[1]; j <= hi[1]; ++j)
      for (int64_t i = lo[0]; i <= hi[0]; ++i) keys->push_back(key({i, j, k}));
}

std::size_t TriangleGrid::count_in(uint64_t k) const {
  const auto it = cubes_.find(k);
  return it == cubes_.end() ? 0 : it->second.size();
}

void TriangleGrid::query_all(const std::vector<Vec3>& lo_m, const std::vector<Vec3>& hi_m, double grow_m,
                             std::vector<int32_t>* out) const {
  out->clear();
  std::vector<uint64_t> keys;
  const Vec3 g = Vec3::Constant(grow_m);
  for (std::size_t i = 0; i < lo_m.size(); ++i) cube_keys(lo_m[i] - g, hi_m[i] + g, &keys);
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  for (uint64_t k : keys) {
    const auto it = cubes_.find(k);
    if (it != cubes_.end()) out->insert(out->end(), it->second.begin(), it->second.end());
  }
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
}

}  // namespace palpate
