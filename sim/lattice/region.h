#pragma once
/// Region following: the lattice region moves (and grows where the material is still deformed) when the
/// contact leaves it, and the state of nodes present before and after is carried over.

#include <cstdint>
#include <vector>

#include "core/grid_hierarchy.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// True when the contact cell (at lat.level) is outside the region or on its outer ring, i.e. its Chebyshev
/// distance from `center` is at least radius_cells: the contact force would then reach fixed or missing nodes.
bool contact_leaves_region(const Lattice& lat, const CellCoord& center, const CellCoord& contact, int radius_cells);

/// Cells of the moved region: the solid cells within radius_cells of `center`, plus the cells of `old` that are
/// still deformed (a node displaced more than keep_m from rest or moving faster than keep_m per second), so
/// deformation is never dropped; sorted ascending.
std::vector<int32_t> followed_region_cells(const GridHierarchy& grid, const Lattice& old, const CellCoord& center,
                                           int radius_cells, double keep_m);

/// Copies position and velocity of every free node of *to that was also a node of `from` (same grid vertex);
/// fixed nodes of *to stay at rest. Returns the number of nodes carried over.
int carry_state(const Lattice& from, Lattice* to);

}  // namespace palpate
