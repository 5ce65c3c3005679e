#pragma once
/// Linking model points to grid cells (paper step 3, eq. (1)).

#include <cstdint>
#include <vector>

#include "core/grid_hierarchy.h"
#include "core/types.h"

namespace palpate {

/// Eq. (1): the cell a point lies in at some level and its local coordinates P = (v - b) / R in [0,1]^3,
/// with b the cell's minimum corner and R its side; plain data, copyable.
struct VertexBinding {
  int32_t cell = 0;            ///< linear cell index at the bound level
  Vec3 local = Vec3::Zero();   ///< local coordinates P, each in [0, 1]
};

/// Binds one point at `level` (1..grid.levels()); points outside the cube are clamped into the nearest cell.
VertexBinding bind_point(const GridHierarchy& grid, int level, const Vec3& p_m);

/// Binds every point at `level`; the result has one binding per point, in order.
std::vector<VertexBinding> bind_vertices(const GridHierarchy& grid, int level,
                                         const std::vector<Vec3>& points_m);

}  // namespace palpate
