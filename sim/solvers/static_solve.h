#pragma once
/// Static equilibrium of a lattice by Newton's method with a sparse LDL^T solve: the reference solver for the
/// continuum checks (sim/material/material.h), not a time integrator. Thread: any; allocates.

#include <cstdint>
#include <vector>

#include <Eigen/SparseCore>

#include "core/result.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// Newton iteration limits and the linear solver of each step.
struct StaticOptions {
  int max_iterations = 30;        ///< Newton steps at most
  double step_tol_m = 1e-14;      ///< stop when the largest node move of a step falls below this
  bool iterative = false;         ///< conjugate gradients with incomplete Cholesky instead of LDL^T (large lattices)
  double cg_tolerance = 1e-12;    ///< relative residual of each conjugate-gradient solve
};

/// What the solve did.
struct StaticReport {
  int iterations = 0;             ///< Newton steps taken
  double max_residual_N = 0.0;    ///< largest free-DOF force imbalance at the end
};

/// Moves the free DOFs of lat->x_m to equilibrium of the springs, gravity (mass_kg g) and f_ext_N (n, or empty).
/// held_dof (3n, dof 3i + axis; empty = every DOF of lat->fixed nodes) marks DOFs kept at their current lat->x_m,
/// which may be displaced from rest (prescribed displacement). On a refined lattice the hanging nodes follow their
/// masters (sim/solvers/free_coords.h; they are put on their faces first). Velocities are left alone. Errors when the system
/// is singular (free rigid modes) or the iteration does not converge, naming the step and residual.
Result<StaticReport> solve_static(Lattice* lat, const std::vector<uint8_t>& held_dof, const std::vector<Vec3>& f_ext_N,
                                  const StaticOptions& options = {});

/// Adds the lattice's tangent stiffness K at lat.x_m (springs, volume and Neo-Hookean terms; f(x + dx) ~ f(x) - K dx)
/// to trip as entries (col[dof a], col[dof b], K_ab); col (3n) numbers the unknown DOFs, -1 for the held ones
/// (FreeCoords::col: hanging nodes' DOFs included, reduced afterwards).
/// clamp_compression drops a compressed spring's transverse term (sim/lattice/forces.h), keeping the springs' part definite.
void add_stiffness_triplets(const Lattice& lat, const std::vector<int>& col, std::vector<Eigen::Triplet<double>>* trip,
                            bool clamp_compression = false);

/// Net spring and cell-volume force on every node at positions x_m (n), including the held ones (there: minus the reaction).
std::vector<Vec3> spring_forces_N(const Lattice& lat, const std::vector<Vec3>& x_m);

}  // namespace palpate
