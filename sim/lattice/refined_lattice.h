#pragma once
/// Refined lattice: fine cells where the tool is, coarse cells elsewhere, in one lattice. The region's cells at the
/// coarse level (spec.level) are kept whole except those chosen for refinement, which are split into their solid
/// children at fine_level. Each cell carries its own calibration (sim/material/material.h at its own edge), so the springs
/// of both sizes are those of the same solid. Fine nodes on the face or edge of a coarse neighbour are hanging
/// (Lattice::hanging): they move with that face (sim/lattice/hanging.h), which keeps the lattice conforming. Node
/// indices, grid_node and slot_of_cell are at fine_level (a coarse cell's slot covers all its fine children), so
/// the contact load, the deformer and region following read it as they read a uniform lattice.

#include <cstdint>
#include <vector>

#include "core/grid_hierarchy.h"
#include "core/result.h"
#include "core/scene.h"
#include "sim/lattice/graded_zone.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// Builds the lattice over coarse_cells (grid indices at spec.level) with the cells listed in `refine` (a subset,
/// same level) split at fine_level (> spec.level). Needs spec.material (any material.model: each cell's springs and
/// volume or Neo-Hookean term take its own edge). Border nodes (touching a solid coarse cell outside the region) and,
/// with spec.fix_floor, the model's lowest node plane are fixed. Errors name what is missing or out of range.
Result<Lattice> build_refined_lattice(const GridHierarchy& grid, const LatticeSpec& spec,
                                      const std::vector<int32_t>& coarse_cells, int fine_level,
                                      const std::vector<int32_t>& refine);

/// Builds the lattice of `leaves` (sim/lattice/graded_zone.h; levels spec.level..fine_level, their union inside coarse_cells,
/// the region at spec.level): each leaf a cell calibrated at its own edge, a node on a coarser leaf's face or edge and
/// off its corners hanging on it. Border and floor nodes fixed as above. Errors as above, or naming a leaf's level.
Result<Lattice> build_refined_lattice(const GridHierarchy& grid, const LatticeSpec& spec,
                                      const std::vector<int32_t>& coarse_cells, int fine_level,
                                      const std::vector<LeafCell>& leaves);

/// The cells of `cells` (at `level`) whose box comes closer than radius_m to p_m: the zone to refine.
std::vector<int32_t> cells_near(const GridHierarchy& grid, int level, const std::vector<int32_t>& cells, const Vec3& p_m,
                                double radius_m);

/// The cells at coarse_level of a refined (or uniform) lattice `lat` that are still deformed: a node displaced more
/// than keep_m from rest or moving faster than keep_m per second. Sorted, unique.
std::vector<int32_t> deformed_coarse_cells(const GridHierarchy& grid, const Lattice& lat, int coarse_level, double keep_m);

/// Carries the state of `from` into *to (both at the same fine level): a free node of *to that is a node of `from`
/// takes its position and velocity, one that is not takes `from`'s displacement and velocity interpolated in the
/// cell of `from` holding its rest position (none: at rest); hanging nodes then follow their faces. Returns the
/// number of nodes carried (copied or interpolated).
int carry_state_refined(const GridHierarchy& grid, const Lattice& from, Lattice* to);

}  // namespace palpate
