#pragma once
/// Upper bounds on a scene's lattice size, computed from the grid's solid cells before any lattice is built,
/// so a scene that would take all memory is refused with the limit named (core/limits.h).

#include <cstdint>

#include "core/grid_hierarchy.h"
#include "core/result.h"
#include "core/scene.h"

namespace palpate {

/// Largest lattice a scene can build.
struct LatticeEstimate {
  int64_t nodes = 0;    ///< grid corners of the solid cells a region may cover
  int64_t springs = 0;  ///< nodes x springs owned per node by the families switched on (3 + 10 + 3)
};

/// Bounds the lattice at spec.level: every solid cell's corners when whole_object (cut mode), else at most the
/// corners of a (2 radius_cells + 1)^3 block of cells, and never more than the object has; with spec.refine, plus
/// the fine-level corners of a cube around the refined zone (its radius and a coarse cell each side).
LatticeEstimate estimate_lattice(const GridHierarchy& grid, const LatticeSpec& spec, bool whole_object);

/// Refuses a scene whose lattice estimate passes kMaxLatticeNodes or kMaxLatticeSprings: "lattice.level 8 with
/// radius_cells 128 may reach 2146689 nodes, more than the limit of 65536 (lower lattice.level or radius_cells)".
Status check_lattice_limits(const GridHierarchy& grid, const Scene& scene);

}  // namespace palpate
