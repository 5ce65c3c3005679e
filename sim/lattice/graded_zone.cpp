#include "sim/lattice/graded_zone.h"

#include <algorithm>
#include <cmath>

#include "sim/material/material.h"

namespace palpate {
namespace {

// How far the closed box of cell `index` at `level` is from p_m: the offset d to its nearest point, with the part
// along `inward` (unit, or zero) counted at 1 / kDepthReach, so the zone reaches that much further into the body.
double zone_distance(const GridHierarchy& grid, int level, int32_t index, const Vec3& p_m, const Vec3& inward) {
  const double l = grid.cell_size_m(level);
  const CellCoord c = grid.coord_of(index, level);
  const Vec3 lo = grid.cube().min_m + l * Vec3(c.i, c.j, c.k);
  const Vec3 d = p_m.cwiseMax(lo).cwiseMin(lo + Vec3::Constant(l)) - p_m;
  const double along = std::max(0.0, d.dot(inward));
  return std::sqrt((d - along * inward).squaredNorm() + along * along / (kDepthReach * kDepthReach));
}

// The leaves with the level of the leaf covering each fine cell (-1: none), kept in step as cells are split.
class Leaves {
 public:
  Leaves(const GridHierarchy& grid, int fine_level)
      : grid_(grid), fine_(fine_level), level_at_(static_cast<std::size_t>(grid.num_cells(fine_level)), -1) {}

  void add(const LeafCell& c) {
    list_.push_back(c);
    mark(c, static_cast<int8_t>(c.level));
  }

  // Replaces leaf k by its solid children (appended).
  void split(std::size_t k) {
    const LeafCell c = list_[k];
    list_[k] = list_.back();
    list_.pop_back();
    mark(c, -1);
    const CellCoord g = grid_.coord_of(c.index, c.level);
    for (int child = 0; child < 8; ++child) {
      const int32_t idx = grid_.linear_index(
          {2 * g.i + (child & 1), 2 * g.j + ((child >> 1) & 1), 2 * g.k + ((child >> 2) & 1)}, c.level + 1);
      if (grid_.solid_cell(idx, c.level + 1)) add({c.level + 1, idx});
    }
  }

  // Whether a leaf two or more levels finer than c touches it (shares a face, an edge or a corner).
  bool touches_finer(const LeafCell& c) const {
    if (c.level + 2 > fine_) return false;
    const int r = 1 << (fine_ - c.level), nf = grid_.cells_per_axis(fine_);
    const CellCoord g = grid_.coord_of(c.index, c.level);
    const int lo[3] = {g.i * r - 1, g.j * r - 1, g.k * r - 1};
    for (int k = std::max(lo[2], 0); k <= std::min(lo[2] + r + 1, nf - 1); ++k)
      for (int j = std::max(lo[1], 0); j <= std::min(lo[1] + r + 1, nf - 1); ++j)
        for (int i = std::max(lo[0], 0); i <= std::min(lo[0] + r + 1, nf - 1); ++i) {
          const bool inside = i > lo[0] && i <= lo[0] + r && j > lo[1] && j <= lo[1] + r && k > lo[2] && k <= lo[2] + r;
          if (!inside && level_at_[static_cast<std::size_t>(grid_.linear_index({i, j, k}, fine_))] >= c.level + 2) return true;
        }
    return false;
  }

  std::vector<LeafCell>& list() { return list_; }

 private:
  void mark(const LeafCell& c, int8_t level) {
    const int r = 1 << (fine_ - c.level);
    const CellCoord g = grid_.coord_of(c.index, c.level);
    for (int k = 0; k < r; ++k)
      for (int j = 0; j < r; ++j)
        for (int i = 0; i < r; ++i)
          level_at_[static_cast<std::size_t>(grid_.linear_index({g.i * r + i, g.j * r + j, g.k * r + k}, fine_))] = level;
  }

  const GridHierarchy& grid_;
  int fine_;
  std::vector<int8_t> level_at_;  // level of the leaf over each fine cell, -1 none (cells at fine_)
  std::vector<LeafCell> list_;
};

void sort_leaves(std::vector<LeafCell>* leaves) {
  std::sort(leaves->begin(), leaves->end(),
            [](const LeafCell& a, const LeafCell& b) { return a.level != b.level ? a.level < b.level : a.index < b.index; });
}

std::vector<int32_t> sorted_unique(std::vector<int32_t> v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

}  // namespace

Vec3 inward_direction(const GridHierarchy& grid, int level, const Vec3& p_m) {
  // the 2 x 2 x 2 cells whose centres are nearest p_m: their solid fractions' difference across the block, per axis
  const double l = grid.cell_size_m(level);
  const Vec3 u = (p_m - grid.cube().min_m) / l - Vec3::Constant(0.5);
  const int n = grid.cells_per_axis(level);
  Vec3 sum = Vec3::Zero();
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 side(corner & 1 ? 1.0 : -1.0, (corner >> 1) & 1 ? 1.0 : -1.0, (corner >> 2) & 1 ? 1.0 : -1.0);
    const CellCoord c{static_cast<int>(std::floor(u.x())) + (corner & 1), static_cast<int>(std::floor(u.y())) + ((corner >> 1) & 1),
                      static_cast<int>(std::floor(u.z())) + ((corner >> 2) & 1)};
    if (c.i < 0 || c.j < 0 || c.k < 0 || c.i >= n || c.j >= n || c.k >= n) continue;
    const int32_t idx = grid.linear_index(c, level);
    if (grid.solid_cell(idx, level)) sum += cell_solid_fraction(grid, idx, level) * side;
  }
  // solid all round or not at all: no direction (a full face of the block against an empty one gives 4)
  return sum.norm() > 1.0 ? Vec3(sum.normalized()) : Vec3::Zero();
}

std::vector<LeafCell> graded_leaves(const GridHierarchy& grid, int coarse_level, const std::vector<int32_t>& coarse_cells,
                                    int fine_level, const Vec3& p_m, double radius_m) {
  const Vec3 inward = inward_direction(grid, fine_level, p_m);
  Leaves leaves(grid, fine_level);
  for (int32_t c : sorted_unique(coarse_cells)) leaves.add({coarse_level, c});
  // split by distance: the cells split to level L + 1 lie within radius_m * 2^(fine_level - 1 - L) of the contact
  for (std::size_t k = 0; k < leaves.list().size();) {
    const LeafCell c = leaves.list()[k];
    const double reach_m = radius_m * static_cast<double>(1 << std::max(0, fine_level - 1 - c.level));
    if (c.level < fine_level && zone_distance(grid, c.level, c.index, p_m, inward) < reach_m) leaves.split(k);
    else ++k;
  }
  // 2:1 between touching leaves
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t k = 0; k < leaves.list().size();) {
      if (leaves.touches_finer(leaves.list()[k])) leaves.split(k), changed = true;
      else ++k;
    }
  }
  sort_leaves(&leaves.list());
  return leaves.list();
}

std::vector<LeafCell> split_leaves(const GridHierarchy& grid, int coarse_level, const std::vector<int32_t>& coarse_cells,
                                   int fine_level, const std::vector<int32_t>& refine) {
  const std::vector<int32_t> split = sorted_unique(refine);
  std::vector<LeafCell> out;
  const int r = 1 << std::max(0, fine_level - coarse_level);
  for (int32_t c : sorted_unique(coarse_cells)) {
    if (!std::binary_search(split.begin(), split.end(), c)) {
      out.push_back({coarse_level, c});
      continue;
    }
    const CellCoord g = grid.coord_of(c, coarse_level);
    for (int k = 0; k < r; ++k)
      for (int j = 0; j < r; ++j)
        for (int i = 0; i < r; ++i) {
          const int32_t idx = grid.linear_index({g.i * r + i, g.j * r + j, g.k * r + k}, fine_level);
          if (grid.solid_cell(idx, fine_level)) out.push_back({fine_level, idx});
        }
  }
  sort_leaves(&out);
  return out;
}

}  // namespace palpate
