#pragma once
/// TriangleBoxGrid: the triangles of a mesh by the cells of a uniform grid that their current box overlaps, kept up to
/// date one triangle at a time, so a box query visits the triangles near the box instead of the whole mesh and gives
/// what testing every triangle gives (the same ids, ascending).

#include <array>
#include <cstdint>
#include <vector>

#include "core/types.h"

namespace palpate {

/// Whether the box of triangle (a, b, c) overlaps [lo_m, hi_m] (faces touching count).
inline bool triangle_box_overlaps(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& lo_m, const Vec3& hi_m) {
  const Vec3 t_lo = a.cwiseMin(b).cwiseMin(c), t_hi = a.cwiseMax(b).cwiseMax(c);
  return (t_lo.array() <= hi_m.array()).all() && (t_hi.array() >= lo_m.array()).all();
}

/// Uniform cells over the mesh's box when built (a box beyond it is clamped into the border cells, so it is still
/// found); about two cells per triangle, a list kept only for the cells a triangle reaches (a surface reaches few
/// of its box's: the bunny subdivided to 3.76M triangles reaches 167k of 7.6M cells), and one list for the
/// triangles too wide to file cell by cell. Copyable. Thread: one at a time (the sim thread in a session).
class TriangleBoxGrid {
 public:
  /// Indexes every triangle at its box in vertices_m.
  void build(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles);
  /// Triangles indexed (0 before build()).
  std::size_t size() const { return ranges_.size(); }
  /// Triangle t's box may have changed (a corner moved, or the slot holds another triangle; t == size() appends):
  /// moves its entries to the cells of its box now. t must be below triangles.size().
  void update(int32_t t, const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles);
  /// Writes the ids of the triangles whose box in vertices_m overlaps [lo_m, hi_m] into *out (cleared first),
  /// ascending: testing every triangle's box gives the same, when every triangle changed since build() was update()d.
  void query(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
             const Vec3& lo_m, const Vec3& hi_m, std::vector<int32_t>* out);
  /// Triangles whose box the last query() tested (each once): its work, a few times its result, not the mesh.
  std::size_t last_tested() const { return last_tested_; }

 private:
  using CellRange = std::array<int32_t, 6>;  // lo x, y, z, hi x, y, z cell indices (inclusive)
  // the cells of a box, and of a triangle's box
  CellRange range_of(const Vec3& lo_m, const Vec3& hi_m) const;
  CellRange box_range(const std::vector<Vec3>& vertices_m, const std::array<int32_t, 3>& tri) const;
  // calls f with the linear index of every cell of r
  template <class F>
  void for_cells(const CellRange& r, F f) const;

  Vec3 origin_m_ = Vec3::Zero();        // the grid's low corner
  double cell_m_ = 1.0;                 // cell edge
  std::array<int32_t, 3> dims_{1, 1, 1};
  // the list of a triangle's cells, or of the wide ones
  static bool wide(const CellRange& r);
  // files triangle t under ranges_[t]
  void add(int32_t t);

  std::vector<int32_t> slot_of_cell_;         // each cell's list in lists_, -1 none (dims x * y * z)
  std::vector<std::vector<int32_t>> lists_;  // triangle ids by occupied cell, in no set order
  std::vector<int32_t> wide_;                // triangles whose box reaches too many cells to file in each
  std::vector<CellRange> ranges_;            // each triangle's cells as indexed (n_t)
  std::vector<uint32_t> stamp_;              // scratch: the last query that tested each triangle (n_t)
  uint32_t query_ = 0;
  std::size_t last_tested_ = 0;
};

}  // namespace palpate
