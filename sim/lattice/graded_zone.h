#pragma once
/// Which cells a refined lattice (sim/lattice/refined_lattice.h) keeps at which level. A graded zone splits the region's
/// coarse cells one level at a time around the contact, finer the closer they are, and then as many more as keep
/// every two touching cells within one level of each other (2:1 across faces, edges and corners), so a hanging node
/// is always the midpoint of an edge or face of a cell one level coarser. A one-jump split keeps the chosen coarse
/// cells' solid children at the fine level beside whole coarse cells. Thread: the sim thread (allocates).
/// (With 2:1 across corners no hanging node's master hangs: a cell split twice fills its parent to the parent's
/// boundary, so a cell holding a master on that boundary would touch cells two levels finer.)

#include <cstdint>
#include <vector>

#include "core/grid_hierarchy.h"
#include "core/types.h"

namespace palpate {

/// A cell of a refined lattice: its level and its linear index at that level.
struct LeafCell {
  int level = 0;      ///< grid level of the cell
  int32_t index = 0;  ///< GridHierarchy::linear_index at that level
};

/// How much further the zone reaches into the body than along its surface: under a Hertz contact of radius a the
/// normal stress on the axis is still p0 / (1 + z^2 / a^2), half the peak one radius down, while on the surface it
/// is zero outside the patch.
inline constexpr double kDepthReach = 2.0;

/// The unit direction from p_m into the body at `level`: towards the solid side of the 2 x 2 x 2 cells around it (their
/// solid fractions' difference across the block, per axis); zero inside the body (solid all round) or away from it.
Vec3 inward_direction(const GridHierarchy& grid, int level, const Vec3& p_m);

/// The leaves of a graded zone over coarse_cells (at coarse_level): a cell at level L < fine_level whose box comes
/// closer than radius_m * 2^(fine_level - 1 - L) to p_m is split into its solid children (the cells split to the
/// fine level lie within radius_m, each coarser ring within twice the next one's radius), distances into the body
/// (inward_direction at fine_level) counted at 1 / kDepthReach; then any leaf touching a leaf two or more levels
/// finer is split until none does. Sorted by level, then index.
std::vector<LeafCell> graded_leaves(const GridHierarchy& grid, int coarse_level, const std::vector<int32_t>& coarse_cells,
                                    int fine_level, const Vec3& p_m, double radius_m);

/// The leaves of a one-jump split: coarse_cells whole, except those also in `refine`, which are replaced by their
/// solid children at fine_level. Sorted by level, then index.
std::vector<LeafCell> split_leaves(const GridHierarchy& grid, int coarse_level, const std::vector<int32_t>& coarse_cells,
                                   int fine_level, const std::vector<int32_t>& refine);

}  // namespace palpate
