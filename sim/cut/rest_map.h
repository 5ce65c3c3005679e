#pragma once
/// Mapping the blade into rest (material) coordinates: a world point is located in the deformed lattice (the
/// region cell whose trilinear map holds it) and taken to the same local coordinates of the cell at rest, so a
/// cut is tested against rest positions and each node's side of the blade does not drift as the object moves.

#include <vector>

#include "core/grid_hierarchy.h"
#include "core/types.h"
#include "sim/cut/cut.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// The rest position of world point p_W_m in the deformed lattice: the trilinear map of the cell holding it,
/// inverted by Newton iterations and walked to a neighbouring cell when the point lies outside; a point outside
/// every cell is extrapolated from the nearest one within two cells, and one farther away is returned unchanged.
Vec3 world_to_rest(const Lattice& lat, const GridHierarchy& grid, const Vec3& p_W_m);

/// One blade edge mapped to rest: the world edge, the pieces it was split into and their end points at rest
/// (pieces + 1). Keeps the edge shared by two quads mapped once, so strips applied in successive frames meet.
struct RestEdge {
  Vec3 tip_W_m = Vec3::Constant(1e300);  ///< world tip
  Vec3 end_W_m = Vec3::Constant(1e300);  ///< world end
  int pieces = 0;                        ///< pieces along the edge
  std::vector<Vec3> rest_m;              ///< piece end points at rest (pieces + 1)
};

/// The quads (world) in rest coordinates: each is split along the blade into pieces no longer than a lattice
/// cell, whose corners are mapped by world_to_rest(). An edge equal to *last (the later edge of the previous
/// quad, also across calls) reuses its mapping; *last becomes the last quad's later edge. Writes into *out
/// (cleared first).
void quads_to_rest(const Lattice& lat, const GridHierarchy& grid, const std::vector<BladeQuad>& quads_W,
                   RestEdge* last, std::vector<BladeQuad>* out);

}  // namespace palpate
