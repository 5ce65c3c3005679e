#pragma once
/// Force terms of the lattice: Hooke springs (eq. 2-3), relative-velocity damping (eq. 4-5), gravity (eq. 6),
/// and the spring stiffness blocks the implicit integrators need.

#include <vector>

#include "sim/lattice/lattice.h"

namespace palpate {

/// Hooke force of spring s on its node a (eq. 2) for d = x_b - x_a; zero for a zero-length spring (no NaN).
Vec3 spring_force_on_a(const Spring& s, const Vec3& d);

/// Stiffness block K_s = -d f_a / d x_a (3x3, symmetric) of spring s at d = x_b - x_a:
/// k [u u^T + (1 - l0/l)(I - u u^T)]. With clamp_compression the transverse term is dropped when l < l0,
/// which keeps K_s positive semi-definite. A zero-length spring gives k I (the rest-direction limit, isotropic).
Mat3 spring_stiffness_block(const Spring& s, const Vec3& d, bool clamp_compression);

/// f = sum of spring, cell volume (sim/material/volume_term.h), damping, gravity and external forces per node (eq. 7) at (x, v).
/// f_ext may be empty (no external force). A zero-length spring exerts no force (no NaN). Fixed nodes get 0.
/// Gravity costs nothing when it is zero.
void compute_forces(const Lattice& lat, const std::vector<Vec3>& x_m, const std::vector<Vec3>& v_m_per_s,
                    const std::vector<Vec3>& f_ext_N, std::vector<Vec3>* f_N);

/// Elastic energy of springs and cell terms (volume, Neo-Hookean) at positions x_m, in J: what compute_forces' elastic
/// part is minus the gradient of.
double elastic_energy_J(const Lattice& lat, const std::vector<Vec3>& x_m);

/// Potential energy of springs, cell volume terms and gravity plus kinetic energy, in J.
double lattice_energy_J(const Lattice& lat);

/// Kinetic energy of the free nodes, in J.
double kinetic_energy_J(const Lattice& lat);

/// Largest |l - l0| / l0 over the springs (0 for none).
double max_strain(const Lattice& lat);

}  // namespace palpate
