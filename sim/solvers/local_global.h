#pragma once
/// Local/global solver for the lattice's backward Euler step (Liu et al. 2013, "Fast simulation of mass-spring
/// systems"): each iteration projects every spring onto its rest length (local) and solves one constant
/// system (M/h^2 + D/h + L) x = b (global). The relative-velocity damping is linear, so it is implicit and
/// part of the constant matrix. The matrix is the same for x, y and z; it is factored (sparse LL^T) once per
/// lattice revision and substep size. The symbolic analysis (fill-reducing ordering, elimination tree) is kept
/// while the free nodes stay the same and every spring's entries are in the analysed pattern: a cut only removes
/// springs, so it refactors numerically with zeros where they were; a new lattice is analysed again only when its
/// pattern differs. Springs removed since the last factorisation (and nothing else changed) are taken out of the
/// factor by a downdate instead: removing a spring of weight w between free nodes a and b changes the matrix by
/// -w (e_a - e_b)(e_a - e_b)^T (-w e_a e_a^T when b is fixed), which only touches the factor's columns on the
/// elimination-tree path from a and b to the root; the springs a cut removes in one frame go up the union of their
/// paths together, each column read once per batch of springs instead of once per spring.

#include <cstdint>
#include <vector>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "sim/lattice/lattice.h"

namespace palpate {

/// One column v of a downdate: v = sum_{k < count} vals[k] e_{rows[k]}, rows in A's numbering, count 1 or 2 (the
/// two ends of a matrix entry, so each is an ancestor-or-self of the other in the elimination tree). Plain data.
struct DowndateColumn {
  int rows[2] = {0, 0};
  double vals[2] = {0.0, 0.0};
  int count = 0;
};

/// Writes a fill-reducing ordering of symmetric pattern `a` (both triangles) into *perm as Eigen's orderings do:
/// METIS's nested dissection of its graph, or Eigen's approximate minimum degree when METIS fails.
void nested_dissection(const Eigen::SparseMatrix<double>& a, Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>* perm);

/// nested_dissection() as an ordering of Eigen's simplicial Cholesky. On a lattice its elimination tree is
/// shallower than approximate minimum degree's: on bunny_cut a downdate path holds 45 000 factor entries on average
/// instead of 75 000 (and the factor 190 000 instead of 194 000).
template <typename StorageIndex>
struct NestedDissectionOrdering {
  using PermutationType = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, StorageIndex>;
  template <typename MatrixType>
  void operator()(const MatrixType& a, PermutationType& perm) const {
    nested_dissection(a, &perm);
  }
};

/// Eigen's simplicial LL^T in nested-dissection order, with downdates of its factor (same ordering and pattern;
/// entries that become zero stay in the pattern).
class DowndatableLLT
    : public Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, NestedDissectionOrdering<int>> {
 public:
  /// Columns taken out together: each sweep goes once up the union of their elimination-tree paths.
  static constexpr int kBatch = 16;
  /// Replaces the factor of A by that of A - V V^T, V's columns `cols`. The result is that of count rank-1
  /// downdates in order, with the same arithmetic, but each factor column on the paths is visited once per kBatch
  /// columns of V instead of once per column. False when A - V V^T is not positive definite: the factor is then
  /// partly updated and must be refactored.
  bool downdate(const DowndateColumn* cols, int count);
  /// x = A^-1 b for n x 3 row-major b and x (the three coordinates of a node side by side): solve() column by
  /// column, with the same arithmetic in the same order (so bit for bit the same x), in one pass over the factor
  /// for the three columns instead of one each: every factor entry and index is read once per triangular solve,
  /// not three times. scratch is grown to 3 n. Leaves x alone when the factorisation failed.
  void solve_rows3(const double* b, double* x, std::vector<double>* scratch) const;
  /// Entries a numeric factorisation in the analysed pattern updates (sum of squared column counts).
  double factor_work() const;
  /// Entries a downdate touches whose nonzero rows (A's numbering; -1 = none) are a and b: the column counts on
  /// the elimination-tree path from the first of them.
  double downdate_work(int a, int b) const;

 private:
  // one batch of at most kBatch columns
  bool downdate_batch(const DowndateColumn* cols, int count);
  std::vector<double> w_;      // the batch's columns in the factor's numbering, row-major (n x kBatch; zero between uses)
  std::vector<uint8_t> on_path_;  // factor columns on the batch's union of paths (n; zero between uses)
};

/// Solver state for one lattice. Not copyable. Thread: the one stepping thread.
class LocalGlobalSolver {
 public:
  /// Takes one substep h_s with `iterations` local/global iterations. f_ext_N (n, or empty) is held constant.
  /// Returns the iterations taken, or -1 when the factorisation failed or the lattice has cell volume terms
  /// (Lattice::volume_Pa, which the matrix does not hold; the lattice is left unchanged).
  int step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int iterations);
  /// Factors (or downdates) the matrix for this lattice and substep unless it already is; false when that failed.
  bool ready(const Lattice& lat, double h_s);
  /// Times the matrix was factored (for tests: once per lattice revision and substep).
  int factorizations() const { return factorizations_; }
  /// Times the matrix's pattern was analysed (for tests: once per free-node set and spring pattern).
  int analyses() const { return analyses_; }
  /// Springs taken out of the factor by downdates (for tests and reports).
  int64_t downdates() const { return downdates_; }
  /// Above this many removed springs at once the matrix is refactored instead. Whatever the limit, a cut whose
  /// downdates would touch more than 0.3 of the entries a numeric factorisation updates refactors (measured
  /// break-even, local_global.cpp).
  void set_max_downdates(int n) { max_downdates_ = n; }

 private:
  using SpMat = Eigen::SparseMatrix<double>;
  bool prepare(const Lattice& lat, double h_s);
  bool fill_values(const Lattice& lat, double h_s);
  // takes springs removed from the factored lattice out of the factor; false when a refactorisation is needed
  bool downdate_removed(const Lattice& lat, double h_s);
  void remember(const Lattice& lat);

  uint64_t revision_ = 0;
  double h_s_ = 0.0;
  bool ok_ = false;
  int factorizations_ = 0;
  int analyses_ = 0;
  bool analysed_ = false;           // a_'s pattern is the one llt_ analysed
  std::vector<int32_t> idx_;        // row of each free node, -1 for fixed ones (n)
  SpMat a_;                         // the free-node matrix (nf x nf), both triangles
  DowndatableLLT llt_;              // its factor
  int64_t downdates_ = 0;
  int max_downdates_ = 2000;
  std::vector<Spring> springs_;     // the springs, masses and damping the factor holds
  std::vector<double> mass_;
  double damping_ = 0.0;
  std::vector<int32_t> removed_;    // indices into springs_ of the springs a cut removed
  std::vector<DowndateColumn> cols_;  // their columns of the downdate
  // constant rhs part, rhs, solution (nf x 3), a node's coordinates side by side: the local step reads and
  // writes whole rows, the solve takes the three columns in one pass
  using Rows3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  Rows3 b0_, b_, x_;
  std::vector<double> solve_scratch_;  // (3 nf)
};

}  // namespace palpate
