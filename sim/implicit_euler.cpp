#include "sim/implicit_euler.h"

#include <algorithm>
#include <cmath>

#include "sim/forces.h"

namespace palpate {
namespace {

// Value index of entry (row, col) of a compressed column matrix whose pattern holds it.
int32_t value_index(const Eigen::SparseMatrix<double>& m, int row, int col) {
  const int* inner = m.innerIndexPtr();
  const int* begin = inner + m.outerIndexPtr()[col];
  const int* end = inner + m.outerIndexPtr()[col + 1];
  return static_cast<int32_t>(std::lower_bound(begin, end, row) - inner);
}

// Adds s * B to the 3x3 block whose columns start at value indices cols[0..2].
void add_block(double* values, const int32_t* cols, const Mat3& b, double s) {
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) values[cols[c] + r] += s * b(r, c);
}

}  // namespace

void ImplicitEulerSolver::prepare(const Lattice& lat) {
  const std::size_t n = lat.num_nodes();
  dof_.assign(n, -1);
  ndof_ = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!lat.fixed[i]) {
      dof_[i] = ndof_;
      ndof_ += 3;
    }
  // block pattern: node diagonals and the couplings of springs between two free nodes
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(9 * (n + 2 * lat.springs.size()));
  auto block = [&](int r0, int c0) {
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) t.emplace_back(r0 + r, c0 + c, 1.0);
  };
  for (std::size_t i = 0; i < n; ++i)
    if (dof_[i] >= 0) block(dof_[i], dof_[i]);
  for (const Spring& s : lat.springs)
    if (dof_[s.a] >= 0 && dof_[s.b] >= 0) {
      block(dof_[s.a], dof_[s.b]);
      block(dof_[s.b], dof_[s.a]);
    }
  j_.resize(ndof_, ndof_);
  j_.setFromTriplets(t.begin(), t.end());
  j_.makeCompressed();
  // where each block's columns start, so assembly writes values directly
  auto starts = [&](int r0, int c0, int32_t* out) {
    for (int c = 0; c < 3; ++c) out[c] = value_index(j_, r0, c0 + c);
  };
  diag_.assign(n, {-1, -1, -1});
  for (std::size_t i = 0; i < n; ++i)
    if (dof_[i] >= 0) starts(dof_[i], dof_[i], diag_[i].data());
  blocks_.assign(lat.springs.size(), {});
  for (std::size_t k = 0; k < lat.springs.size(); ++k) {
    const Spring& s = lat.springs[k];
    auto& b = blocks_[k];
    b.fill(-1);
    if (dof_[s.a] >= 0) starts(dof_[s.a], dof_[s.a], &b[0]);
    if (dof_[s.b] >= 0) starts(dof_[s.b], dof_[s.b], &b[3]);
    if (dof_[s.a] >= 0 && dof_[s.b] >= 0) {
      starts(dof_[s.a], dof_[s.b], &b[6]);
      starts(dof_[s.b], dof_[s.a], &b[9]);
    }
  }
  ldlt_.analyzePattern(j_);
  g_.resize(ndof_);
  delta_.resize(ndof_);
  revision_ = lat.revision;
}

void ImplicitEulerSolver::assemble(const Lattice& lat, double h_s, const std::vector<Vec3>& x_m) {
  double* v = j_.valuePtr();
  std::fill(v, v + j_.nonZeros(), 0.0);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (dof_[i] >= 0) add_block(v, diag_[i].data(), Mat3::Identity(), lat.mass_kg[i]);
  const Mat3 damping = h_s * lat.damping_Ns_per_m * Mat3::Identity();
  for (std::size_t k = 0; k < lat.springs.size(); ++k) {
    const Spring& s = lat.springs[k];
    const Mat3 b = damping + h_s * h_s * spring_stiffness_block(s, x_m[s.b] - x_m[s.a], true);
    const auto& blk = blocks_[k];
    if (blk[0] >= 0) add_block(v, &blk[0], b, 1.0);
    if (blk[3] >= 0) add_block(v, &blk[3], b, 1.0);
    if (blk[6] >= 0) {
      add_block(v, &blk[6], b, -1.0);
      add_block(v, &blk[9], b, -1.0);
    }
  }
}

int ImplicitEulerSolver::step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int max_iterations) {
  if (lat->revision != revision_ || dof_.size() != lat->num_nodes()) prepare(*lat);
  const std::size_t n = lat->num_nodes();
  x0_m_ = lat->x_m;
  v0_m_per_s_ = lat->v_m_per_s;
  v_m_per_s_ = v0_m_per_s_;
  x_m_.resize(n);
  const double tol_m_per_s = 1e-9 * lat->cell_m / h_s;
  int it = 0;
  while (it < std::max(1, max_iterations)) {
    // residual g(v) = M (v - v0) - h f(x0 + h v, v)
    for (std::size_t i = 0; i < n; ++i) x_m_[i] = lat->fixed[i] ? x0_m_[i] : Vec3(x0_m_[i] + h_s * v_m_per_s_[i]);
    compute_forces(*lat, x_m_, v_m_per_s_, f_ext_N, &f_N_);
    for (std::size_t i = 0; i < n; ++i)
      if (dof_[i] >= 0)
        g_.segment<3>(dof_[i]) = lat->mass_kg[i] * (v_m_per_s_[i] - v0_m_per_s_[i]) - h_s * f_N_[i];
    assemble(*lat, h_s, x_m_);
    ldlt_.factorize(j_);
    if (ldlt_.info() != Eigen::Success) return -1;
    delta_ = ldlt_.solve(-g_);
    ++it;
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      if (dof_[i] >= 0) {
        const Vec3 d = delta_.segment<3>(dof_[i]);
        v_m_per_s_[i] += d;
        worst = std::max(worst, d.cwiseAbs().maxCoeff());
      }
    if (!(worst > tol_m_per_s)) break;  // converged (or non-finite: the caller's check catches it)
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (lat->fixed[i]) continue;
    lat->v_m_per_s[i] = v_m_per_s_[i];
    lat->x_m[i] = x0_m_[i] + h_s * v_m_per_s_[i];
  }
  return it;
}

}  // namespace palpate
