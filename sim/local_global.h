#pragma once
/// Local/global solver for the lattice's backward Euler step (Liu et al. 2013, "Fast simulation of mass-spring
/// systems"): each iteration projects every spring onto its rest length (local) and solves one constant
/// system (M/h^2 + D/h + L) x = b (global). The relative-velocity damping is linear, so it is implicit and
/// part of the constant matrix. The matrix is the same for x, y and z; it is factored (sparse LL^T) once per
/// lattice revision and substep size. The symbolic analysis (fill-reducing ordering, elimination tree) is kept
/// while the free nodes stay the same and every spring's entries are in the analysed pattern: a cut only removes
/// springs, so it refactors numerically with zeros where they were; a new lattice is analysed again only when its
/// pattern differs.

#include <cstdint>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "sim/lattice.h"

namespace palpate {

/// Solver state for one lattice. Not copyable. Thread: the one stepping thread.
class LocalGlobalSolver {
 public:
  /// Takes one substep h_s with `iterations` local/global iterations. f_ext_N (n, or empty) is held constant.
  /// Returns the iterations taken, or -1 when the factorisation failed (the lattice is left unchanged).
  int step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int iterations);
  /// Times the matrix was factored (for tests: once per lattice revision and substep).
  int factorizations() const { return factorizations_; }
  /// Times the matrix's pattern was analysed (for tests: once per free-node set and spring pattern).
  int analyses() const { return analyses_; }

 private:
  using SpMat = Eigen::SparseMatrix<double>;
  bool prepare(const Lattice& lat, double h_s);
  bool fill_values(const Lattice& lat, double h_s);

  uint64_t revision_ = 0;
  double h_s_ = 0.0;
  bool ok_ = false;
  int factorizations_ = 0;
  int analyses_ = 0;
  bool analysed_ = false;           // a_'s pattern is the one llt_ analysed
  std::vector<int32_t> idx_;        // row of each free node, -1 for fixed ones (n)
  SpMat a_;                         // the free-node matrix (nf x nf), both triangles
  Eigen::SimplicialLLT<SpMat> llt_; // its factor
  Eigen::MatrixX3d b0_, b_, x_;     // constant rhs part, rhs, solution (nf x 3)
};

}  // namespace palpate
