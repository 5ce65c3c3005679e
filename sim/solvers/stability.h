#pragma once
/// Cheap stability bounds of the lattice (Gershgorin on M^-1 K and M^-1 C) and the explicit Euler check.

#include <string>

#include "core/result.h"
#include "core/scene.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// Bounds on the lattice's fastest dynamics.
struct StabilityBound {
  double omega_max_rad_per_s = 0.0;  ///< sqrt(max_i 2 sum_j k_ij / m_i)
  double damping_rate_per_s = 0.0;   ///< max_i 2 sum_j c_ij / m_i
  double max_stable_dt_s = 0.0;      ///< largest symplectic Euler step with h^2 w^2 + 2 h g <= 4 * safety
};

/// Computes the bound over free nodes (safety factor in (0, 1], e.g. 0.8).
StabilityBound stability_bound(const Lattice& lat, double safety);

/// Whether the paper's explicit Euler (eq. 8) is stable at a step: forward Euler on a spring of stiffness k and
/// relative damping c needs h <= c / k (|1 + h lambda| <= 1 for an underdamped mode), and h <= 2 / damping rate
/// for the overdamped ones.
struct ExplicitEulerCheck {
  bool stable = true;            ///< both bounds hold
  double max_dt_s = 0.0;         ///< min(c / k_max, 2 / damping rate); 0 when there is no damping
  std::string message;           ///< empty when stable; otherwise names dt, the bound and the parameters
};

/// Checks explicit Euler on a built lattice at step dt_s.
ExplicitEulerCheck check_explicit_euler(const Lattice& lat, double dt_s);

/// Checks explicit Euler from scene parameters alone (start-up), assuming a full lattice (32 springs a node).
ExplicitEulerCheck check_explicit_euler(const LatticeSpec& spec, double dt_s);

/// A start-up warning for the scene's integrator at frame step dt_s, or "" when there is nothing to say: explicit
/// Euler past its bound, or symplectic Euler / RK4 needing more substeps than substeps / max_substeps allow.
std::string integrator_warning(const LatticeSpec& spec, double dt_s);

/// The explicit schemes on a material lattice (spec.material.enabled) with cells of cell_m: the bound at a full
/// interior node (mass rho l^3; 6 edges of 4 k_e, 12 face diagonals of 2 k_s, 8 body diagonals of k_s, and the 8
/// cells' volume or Neo-Hookean terms), which is the least any node of the lattice needs (a node on the surface
/// carries less mass for its springs). A scheme that needs more substeps there than lattice.substeps /
/// max_substeps allow, or explicit Euler past its bound, diverges on every lattice the scene can build: an error
/// naming the keys, the figures and what to change. Implicit Euler and local/global: always accepted.
Status check_material_integrator(const LatticeSpec& spec, double cell_m, double dt_s);

}  // namespace palpate
