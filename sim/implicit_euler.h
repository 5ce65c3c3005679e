#pragma once
/// Implicit (backward) Euler for the lattice, Baraff-Witkin style: Newton on the velocity update with the
/// system J = M + h D + h^2 K, K the spring stiffness kept positive semi-definite under compression, solved by a
/// sparse LDL^T whose symbolic analysis is done once per lattice revision.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "sim/lattice.h"

namespace palpate {

/// Newton solver state for one lattice. Not copyable; allocates when the lattice revision changes.
/// Thread: the one stepping thread.
class ImplicitEulerSolver {
 public:
  /// Takes one backward Euler substep h_s with at most max_iterations Newton iterations (stops early when the
  /// velocity update moves no node by more than 1e-9 of a cell). f_ext_N (n, or empty) is held constant.
  /// Returns the iterations taken, or -1 when the factorisation failed (the lattice is left unchanged).
  int step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int max_iterations);

 private:
  using SpMat = Eigen::SparseMatrix<double>;
  void prepare(const Lattice& lat);
  void assemble(const Lattice& lat, double h_s, const std::vector<Vec3>& x_m);

  uint64_t revision_ = 0;
  int ndof_ = 0;
  std::vector<int32_t> dof_;                     // first dof of each node, -1 for fixed ones (n)
  std::vector<std::array<int32_t, 3>> diag_;     // value index of each column's first block row, node block (n)
  std::vector<std::array<int32_t, 12>> blocks_;  // same for the aa, bb, ab, ba blocks of each spring, -1 if fixed (n_s)
  SpMat j_;                                      // Newton matrix (ndof x ndof)
  Eigen::SimplicialLDLT<SpMat> ldlt_;
  Eigen::VectorXd g_, delta_;                    // residual and update (ndof)
  std::vector<Vec3> x0_m_, v0_m_per_s_, x_m_, v_m_per_s_, f_N_;  // (n)
};

}  // namespace palpate
