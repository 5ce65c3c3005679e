#pragma once
/// Hanging nodes of a refined lattice (Lattice::hanging): a fine node on the face of a coarse cell moves with that
/// face. Positions and velocities are spread from the coarse corners to the hanging nodes (x = P q), forces are
/// folded back onto the corners (P^T f), which is how a solver sees the constrained lattice. Thread: the sim thread.

#include <vector>

#include "core/types.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// Sets each hanging node's entry of *v (positions, velocities or a solver's increment, n) to the weighted sum of
/// its masters' entries, in list order (masters that hang themselves come first). No effect without hanging nodes.
void spread_hanging(const Lattice& lat, std::vector<Vec3>* v);

/// Adds each hanging node's entry of *f (forces or residuals, n) to its masters by their weights and zeroes it, in
/// reverse list order: the force the constrained lattice's free coordinates feel. No effect without hanging nodes.
void fold_hanging(const Lattice& lat, std::vector<Vec3>* f);

/// Marks the hanging nodes in *mask (n; set to 1), e.g. to leave them out of a solver's free coordinates.
void mark_hanging(const Lattice& lat, std::vector<uint8_t>* mask);

}  // namespace palpate
