#pragma once
/// Implicit (backward) Euler for the lattice, Baraff-Witkin style: Newton on the velocity update with the
/// system J = M + h D + h^2 K, K the spring stiffness kept positive semi-definite under compression, solved
/// matrix-free by conjugate gradients with a 3x3 block-Jacobi preconditioner, warm-started from the previous
/// update. J is kept as one symmetric 3x3 block per spring plus one per node, so a product J p is one sweep over
/// the springs (and, with a volume term, over the cells: each adds the rank-one Gauss-Newton block of its (J - 1)^2); the mass term keeps J well conditioned at frame-size steps (condition number bounded by
/// 1 + h^2 w_max^2 + h g, independent of the lattice size), so the iteration count does not grow with n.

#include <array>
#include <cstdint>
#include <vector>

#include "sim/lattice/lattice.h"
#include "sim/material/neo_hookean_term.h"

namespace palpate {

/// Newton solver state for one lattice. Not copyable; allocates only when the lattice revision changes.
/// Thread: the one stepping thread.
class ImplicitEulerSolver {
 public:
  ImplicitEulerSolver() = default;
  ImplicitEulerSolver(const ImplicitEulerSolver&) = delete;
  ImplicitEulerSolver& operator=(const ImplicitEulerSolver&) = delete;

  /// Relative residual |J d + g| / |g| at which the conjugate gradient solve of a Newton system stops.
  static constexpr double kCgTolerance = 1e-6;

  /// Takes one backward Euler substep h_s with at most max_iterations Newton iterations (stops early when the
  /// velocity update moves no node by more than 1e-9 of a cell). f_ext_N (n, or empty) is held constant.
  /// Returns the iterations taken, or -1 when the linear solve broke down (a non-positive curvature or a
  /// non-finite residual; the lattice is left unchanged).
  int step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int max_iterations);

  /// Takes the backward Euler substep h_s by projected Newton: each cell's Neo-Hookean tangent has its negative
  /// eigenvalues raised to zero (so J stays positive definite and every Newton step descends), and each step is
  /// halved until it lowers the substep's incremental potential (kinetic, elastic, damping and load terms, whose
  /// gradient is the residual), for at most max_iterations steps or until a step moves no node by 1e-6 of a cell.
  /// For the substeps step() cannot take (a squashed cell's indefinite tangent breaks its conjugate gradients
  /// at any split): the result is the minimum of the same potential, not an explicit guess. Returns the iterations
  /// taken, or -1 when the potential was not finite at the start or a solve went non-finite (the lattice unchanged).
  /// deadline_ns > 0 (core/clock.h, monotonic_ns): past it, after the first step, the lattice takes the last iterate
  /// and *out_of_time (when given) is set.
  int projected_step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int max_iterations,
                     int64_t deadline_ns = 0, bool* out_of_time = nullptr);

  /// Conjugate gradient iterations of the last Newton solve (for benchmarks and tests).
  int last_cg_iterations() const { return last_cg_iterations_; }
  /// Conjugate gradient iterations over every Newton solve of the last step (for benchmarks and tests).
  int step_cg_iterations() const { return step_cg_iterations_; }
  /// Relative residual reached by the last Newton solve (for tests).
  double last_cg_residual() const { return last_cg_residual_; }

 private:
  void prepare(const Lattice& lat);
  void assemble(const Lattice& lat, double h_s, const std::vector<Vec3>& x_m);
  void multiply(const Lattice& lat, const std::vector<Vec3>& p, std::vector<Vec3>* out) const;
  bool solve(const Lattice& lat);
  // a substep's start: the solver sized for lat, its hanging nodes spread, x0, v0 and v taken from it
  void begin_step(Lattice* lat);
  // a substep's end: lat at x0 + h v with velocities v, and v - v0 kept as the next step's warm start
  void finish_step(Lattice* lat, double h_s);
  // the residual h f - M (v - v0) at velocities v_m_per_s_ into rhs_ (x_m_ set to x0 + h v), reduced to the free
  // coordinates of a refined or held lattice
  void residual(const Lattice& lat, double h_s, const std::vector<Vec3>& f_ext_N);
  // the substep's incremental potential at velocities v (J; its gradient is minus the residual): 1/2 |v - v0|_M^2,
  // the lattice's elastic energy at x0 + h v, the springs' damping h/2 c |v_b - v_a|^2, less the work h (m g + f_ext) . v
  double incremental_potential(const Lattice& lat, double h_s, const std::vector<Vec3>& v, const std::vector<Vec3>& f_ext_N);

  uint64_t revision_ = 0;
  std::size_t num_springs_ = 0;
  int last_cg_iterations_ = 0;
  int step_cg_iterations_ = 0;
  double last_cg_residual_ = 0.0;
  std::vector<Mat3> spring_block_;       // h c I + h^2 K_s of each spring (n_s)
  std::vector<Mat3> node_block_;         // diagonal block m I + sum of its springs' blocks (n)
  std::vector<Mat3> node_block_inv_;     // its inverse: the preconditioner, zero for fixed nodes (n)
  std::vector<std::array<Vec3, 8>> cell_c_;  // volume term: cof(F) g_a of each cell's corners (n_c x 8; sim/material/volume_term.h)
  std::vector<NeoHookeanCell> neo_;      // Neo-Hookean term: each cell's tangent state (n_c; sim/material/neo_hookean_term.h)
  double neo_h2_ = 0.0;                  // h^2, the factor on that term's tangent
  bool projected_ = false;               // projected_step: the cells' tangents are neo_h9_, not neo_
  std::vector<Mat9> neo_h9_;             // projected_step: l^3 times each cell's projected Hessian on vec F (n_c)
  mutable std::vector<Vec3> neo_y_;      // scratch for its product (n; sized once per lattice)
  mutable std::vector<Vec3> p_spread_;   // a refined lattice's CG direction with its hanging nodes spread (n)
  std::vector<double> cell_w_;           // h^2 l^3 psi''(J) per cell: its Gauss-Newton blocks are cell_w_ c_a c_b^T (n_c)
  std::vector<Vec3> rhs_, delta_, r_, z_, p_, jp_;  // CG vectors, zero at fixed nodes (n)
  std::vector<Vec3> last_dv_m_per_s_;    // velocity change of the previous step: the first solve's warm start (n)
  std::vector<Vec3> x0_m_, v0_m_per_s_, x_m_, v_m_per_s_, f_N_;  // (n)
  std::vector<Vec3> trial_v_, trial_x_;  // projected_step's line search: trial velocities and positions (n)
};

}  // namespace palpate
