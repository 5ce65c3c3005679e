#include "sim/lattice/region.h"

#include <algorithm>
#include <cstdlib>
#include <unordered_map>

namespace palpate {

bool contact_leaves_region(const Lattice& lat, const CellCoord& center, const CellCoord& contact, int radius_cells) {
  const int d = std::max({std::abs(contact.i - center.i), std::abs(contact.j - center.j), std::abs(contact.k - center.k)});
  if (d >= radius_cells && radius_cells > 0) return true;
  const int n = lat.cells_per_axis;
  if (contact.i < 0 || contact.j < 0 || contact.k < 0 || contact.i >= n || contact.j >= n || contact.k >= n) return true;
  return lat.slot_of_cell[static_cast<std::size_t>(contact.i + n * (contact.j + n * contact.k))] < 0;
}

std::vector<int32_t> followed_region_cells(const GridHierarchy& grid, const Lattice& old, const CellCoord& center,
                                           int radius_cells, double keep_m) {
  std::vector<int32_t> cells = region_cells(grid, old.level, center, radius_cells);
  for (std::size_t s = 0; s < old.cells.size(); ++s) {
    bool deformed = false;
    for (int32_t node : old.cell_nodes[s])
      deformed = deformed || (old.x_m[node] - old.rest_m[node]).norm() > keep_m || old.v_m_per_s[node].norm() > keep_m;
    if (deformed) cells.push_back(old.cells[s]);
  }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  return cells;
}

int carry_state(const Lattice& from, Lattice* to) {
  std::unordered_map<int32_t, int32_t> index;
  index.reserve(from.num_nodes());
  for (std::size_t i = 0; i < from.num_nodes(); ++i) index.emplace(from.grid_node[i], static_cast<int32_t>(i));
  int carried = 0;
  for (std::size_t i = 0; i < to->num_nodes(); ++i) {
    if (to->fixed[i]) continue;
    const auto it = index.find(to->grid_node[i]);
    if (it == index.end()) continue;
    to->x_m[i] = from.x_m[it->second];
    to->v_m_per_s[i] = from.v_m_per_s[it->second];
    ++carried;
  }
  return carried;
}

}  // namespace palpate
