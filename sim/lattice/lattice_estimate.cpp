#include "sim/lattice/lattice_estimate.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "core/limits.h"

namespace palpate {

LatticeEstimate estimate_lattice(const GridHierarchy& grid, const LatticeSpec& spec, bool whole_object) {
  const int level = std::clamp(spec.level, 1, grid.levels());
  const int64_t n = grid.cells_per_axis(level);
  const int64_t nv = n + 1;
  // the distinct corners of all solid cells: what a lattice over the whole object has
  std::vector<uint8_t> corner(static_cast<std::size_t>(nv * nv * nv), 0);
  int64_t object_nodes = 0;
  for (int64_t idx = 0; idx < grid.num_cells(level); ++idx) {
    if (!grid.solid_cell(static_cast<int32_t>(idx), level)) continue;
    const CellCoord c = grid.coord_of(static_cast<int32_t>(idx), level);
    for (int k = 0; k < 8; ++k) {
      uint8_t& m = corner[static_cast<std::size_t>((c.i + (k & 1)) + nv * ((c.j + ((k >> 1) & 1)) + nv * (c.k + ((k >> 2) & 1))))];
      object_nodes += m == 0;
      m = 1;
    }
  }
  LatticeEstimate e;
  e.nodes = object_nodes;
  if (!whole_object) {
    const int64_t w = std::min<int64_t>(n, 2 * static_cast<int64_t>(spec.radius_cells) + 1);
    e.nodes = std::min(e.nodes, (w + 1) * (w + 1) * (w + 1));
  }
  // springs owned by a node (it is their lowest corner): 3 axis edges, 6 face and 4 body diagonals, 3 skip-one
  const int64_t per_node = (spec.structural_N_per_m > 0.0 ? 3 : 0) + (spec.shear_N_per_m > 0.0 ? 10 : 0) +
                           (spec.bend_N_per_m > 0.0 ? 3 : 0);
  // a refined zone: at most the fine nodes of a cube around the ball of radius_m, widened by a coarse cell (the
  // zone takes every coarse cell the ball comes near), on top of the coarse nodes
  if (spec.refine.level > level && spec.refine.level <= grid.levels()) {
    const double fine_m = grid.cell_size_m(spec.refine.level), coarse_m = grid.cell_size_m(level);
    const double side = std::min((2.0 * (spec.refine.radius_m + coarse_m)) / fine_m + 1.0,
                                 static_cast<double>(grid.cells_per_axis(spec.refine.level)) + 1.0);
    e.nodes += static_cast<int64_t>(std::min(side * side * side, 1e15));
  }
  e.springs = e.nodes * per_node;
  return e;
}

Status check_lattice_limits(const GridHierarchy& grid, const Scene& scene) {
  const bool whole = scene.mode == InteractionMode::kCut;
  const LatticeEstimate e = estimate_lattice(grid, scene.lattice, whole);
  const bool refined = scene.lattice.refine.level > scene.lattice.level;
  std::string what = "lattice.level " + std::to_string(scene.lattice.level) +
                     (whole ? " over the whole object (cut mode)"
                            : " with radius_cells " + std::to_string(scene.lattice.radius_cells));
  if (refined) {
    char r[48];
    std::snprintf(r, sizeof r, "%g", scene.lattice.refine.radius_m);
    what += " refined to level " + std::to_string(scene.lattice.refine.level) + " within " + r + " m";
  }
  const char* advice = whole     ? " (lower lattice.level)"
                       : refined ? " (lower lattice.refine.level or lattice.refine.radius_m)"
                                 : " (lower lattice.level or lattice.radius_cells)";
  if (e.nodes > kMaxLatticeNodes)
    return make_error(what, " may reach ", std::to_string(e.nodes), " nodes, more than the limit of ",
                      std::to_string(kMaxLatticeNodes), advice);
  if (e.springs > kMaxLatticeSprings)
    return make_error(what, " may reach ", std::to_string(e.springs), " springs, more than the limit of ",
                      std::to_string(kMaxLatticeSprings), advice);
  return Ok{};
}

}  // namespace palpate
