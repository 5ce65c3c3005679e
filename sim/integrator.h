#pragma once
/// Time integration of the lattice: the paper's explicit Euler (eq. 8) and symplectic Euler with automatic substeps.

#include <vector>

#include "core/scene.h"
#include "sim/lattice.h"

namespace palpate {

/// Cheap bounds on the lattice's fastest dynamics (Gershgorin on M^-1 K and M^-1 C).
struct StabilityBound {
  double omega_max_rad_per_s = 0.0;  ///< sqrt(max_i 2 sum_j k_ij / m_i)
  double damping_rate_per_s = 0.0;   ///< max_i 2 sum_j c_ij / m_i
  double max_stable_dt_s = 0.0;      ///< largest symplectic Euler step with h^2 w^2 + 2 h g <= 4 * safety
};

/// Computes the bound over free nodes (safety factor in (0, 1], e.g. 0.8).
StabilityBound stability_bound(const Lattice& lat, double safety);

/// What one step did.
struct StepReport {
  int substeps = 0;      ///< substeps taken
  bool finite = true;    ///< false when the state went non-finite (the caller resets it)
};

/// Scratch buffers reused across steps (no allocation after the first step of a lattice).
struct IntegratorWorkspace {
  std::vector<Vec3> f_N;  ///< forces (n)
};

/// Advances the lattice by dt_s. explicit_euler takes one step (eq. 8: x uses the old velocity);
/// symplectic_euler takes ceil(dt / max_stable_dt) substeps, at most max_substeps.
/// f_ext_N (n, or empty) is held constant over the step. Fixed nodes stay at rest.
StepReport step_lattice(Lattice* lat, IntegratorKind kind, double dt_s, int max_substeps,
                        const std::vector<Vec3>& f_ext_N, IntegratorWorkspace* ws);

}  // namespace palpate
