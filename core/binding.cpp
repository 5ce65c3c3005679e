#include "core/binding.h"

namespace palpate {

VertexBinding bind_point(const GridHierarchy& grid, int level, const Vec3& p_m) {
  const CellCoord c = grid.cell_of(p_m, level);
  const Vec3 b_m = grid.cell_min_m(c, level);
  const double r_m = grid.cell_size_m(level);
  VertexBinding binding;
  binding.cell = grid.linear_index(c, level);
  // eq. (1), clamped because rounding (or a point outside the cube) can leave [0, 1] by a hair
  binding.local = ((p_m - b_m) / r_m).cwiseMax(0.0).cwiseMin(1.0);
  return binding;
}

std::vector<VertexBinding> bind_vertices(const GridHierarchy& grid, int level,
                                         const std::vector<Vec3>& points_m) {
  std::vector<VertexBinding> bindings;
  bindings.reserve(points_m.size());
  for (const Vec3& p : points_m) bindings.push_back(bind_point(grid, level, p));
  return bindings;
}

}  // namespace palpate
