#pragma once
/// Force terms of the lattice: Hooke springs (eq. 2-3), relative-velocity damping (eq. 4-5), gravity (eq. 6).

#include <vector>

#include "sim/lattice.h"

namespace palpate {

/// f = sum of spring, damping, gravity and external forces per node (eq. 7) at state (x, v).
/// f_ext may be empty (no external force). A zero-length spring exerts no force (no NaN). Fixed nodes get 0.
void compute_forces(const Lattice& lat, const std::vector<Vec3>& x_m, const std::vector<Vec3>& v_m_per_s,
                    const std::vector<Vec3>& f_ext_N, std::vector<Vec3>* f_N);

/// Potential energy of springs and gravity plus kinetic energy, in J.
double lattice_energy_J(const Lattice& lat);

}  // namespace palpate
