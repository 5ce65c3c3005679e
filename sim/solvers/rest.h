#pragma once
/// Rest detection: a lattice whose kinetic energy and net node forces are under thresholds is not stepped.

#include <vector>

#include "sim/lattice/lattice.h"

namespace palpate {

/// True when the free nodes' kinetic energy is below kinetic_J and every node's net force (springs, damping,
/// gravity and f_ext_N, which may be empty) is below force_N. *scratch holds the forces (n).
bool lattice_at_rest(const Lattice& lat, const std::vector<Vec3>& f_ext_N, double kinetic_J, double force_N,
                     std::vector<Vec3>* scratch);

/// Largest |f| over f_N (0 for an empty vector).
double max_force_N(const std::vector<Vec3>& f_N);

}  // namespace palpate
