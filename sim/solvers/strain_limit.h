#pragma once
/// Strain limiting (Provot 1995): springs strained past a limit are projected back, mass-weighted, and the
/// relative velocity that strains them further is removed, so no spring runs away whatever the step.

#include "sim/lattice/lattice.h"

namespace palpate {

/// Projects every spring into rest * [1 - limit, 1 + limit] with `iterations` Gauss-Seidel sweeps (fixed nodes do
/// not move). limit > 0. Returns the number of spring corrections made.
int limit_strain(Lattice* lat, double limit, int iterations);

}  // namespace palpate
