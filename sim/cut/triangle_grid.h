#pragma once
/// TriangleGrid: a hash of rest-space cubes to the triangles whose box overlaps them, so a cut finds the
/// triangles near the blade's sweep without visiting the whole mesh. Entries are only added: a triangle replaced
/// by a piece of itself keeps its cubes (a superset), so a query may return a few more than overlap, never fewer.

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/types.h"

namespace palpate {

/// Cubes of edge cube_m (> 0) over rest positions. Copyable. Thread: one at a time.
class TriangleGrid {
 public:
  TriangleGrid() = default;
  /// Indexes every triangle of the mesh (rest positions).
  TriangleGrid(double cube_m, const std::vector<Vec3>& rest_m, const std::vector<std::array<int32_t, 3>>& triangles);
  /// Registers triangle id t (corners at rest) in every cube its box overlaps.
  void add(int32_t t, const Vec3& a_m, const Vec3& b_m, const Vec3& c_m);
  /// The ids registered in the cubes any of the boxes [lo_m[i] - grow_m, hi_m[i] + grow_m] overlaps, each once,
  /// ascending, into *out (cleared first). Each cube is visited once however many boxes overlap it.
  void query_all(const std::vector<Vec3>& lo_m, const std::vector<Vec3>& hi_m, double grow_m,
                 std::vector<int32_t>* out) const;
  /// Triangle entries in the cube of key k (see cube_keys()).
  std::size_t count_in(uint64_t k) const;
  /// Appends the keys of the cubes the box [lo_m, hi_m] overlaps to *keys (at most 256 a side).
  void cube_keys(const Vec3& lo_m, const Vec3& hi_m, std::vector<uint64_t>* keys) const;
  /// Cube edge length.
  double cube_m() const { return cube_m_; }

 private:
  std::array<int64_t, 3> cube_of(const Vec3& p_m) const;
  static uint64_t key(const std::array<int64_t, 3>& c);

  double cube_m_ = 1.0;
  std::unordered_map<uint64_t, std::vector<int32_t>> cubes_;  // cube key -> triangle ids
};

}  // namespace palpate
