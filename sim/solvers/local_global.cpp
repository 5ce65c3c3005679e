#include "sim/solvers/local_global.h"

#include <algorithm>
#include <cmath>

#include <metis.h>

namespace palpate {

namespace {

// Value index of entry (row, col) of a compressed column matrix, or -1 when its pattern does not hold it.
int32_t value_index(const Eigen::SparseMatrix<double>& m, int row, int col) {
  const int* inner = m.innerIndexPtr();
  const int* begin = inner + m.outerIndexPtr()[col];
  const int* end = inner + m.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  return it != end && *it == row ? static_cast<int32_t>(it - inner) : -1;
}

// Downdates cost more per entry than a factorisation (three multiplications and two additions each, scattered
// through the path's columns): on bunny_cut (1846 nodes, nested dissection, 1 iteration, thread CPU time) the
// frames whose springs' paths add up to 0.11-0.13 of factor_work() downdated in 5-7 ms, and a numeric
// factorisation takes about 15 ms, so the two break even near 0.3 (paths that share columns cost less together
// than their sum says, so the estimate errs toward refactoring). Past this ratio, refactor.
constexpr double kDowndateWorkRatio = 0.3;

}  // namespace

void nested_dissection(const Eigen::SparseMatrix<double>& a, Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>* perm) {
  // METIS wants the graph without its diagonal, in compressed rows (a is symmetric: its columns will do)
  const int n = static_cast<int>(a.cols());
  std::vector<idx_t> xadj(static_cast<std::size_t>(n) + 1, 0), adjncy, order(static_cast<std::size_t>(n)),
      inverse(static_cast<std::size_t>(n));
  adjncy.reserve(static_cast<std::size_t>(a.nonZeros()));
  for (int j = 0; j < n; ++j) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, j); it; ++it)
      if (it.index() != j) adjncy.push_back(static_cast<idx_t>(it.index()));
    xadj[static_cast<std::size_t>(j) + 1] = static_cast<idx_t>(adjncy.size());
  }
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  idx_t nv = n;
  // order[k] = the row eliminated k-th, which is what an Eigen ordering gives (the inverse of the permutation the
  // factor applies)
  if (n > 1 && METIS_NodeND(&nv, xadj.data(), adjncy.data(), nullptr, options, order.data(), inverse.data()) == METIS_OK) {
    perm->resize(n);
    for (int k = 0; k < n; ++k) perm->indices()[k] = static_cast<int>(order[static_cast<std::size_t>(k)]);
    return;
  }
  Eigen::AMDOrdering<int>()(a, *perm);
}

void DowndatableLLT::solve_rows3(const double* b, double* x, std::vector<double>* scratch) const {
  if (m_info != Eigen::Success) return;
  const int n = static_cast<int>(m_matrix.cols());
  if (scratch->size() < 3 * static_cast<std::size_t>(n)) scratch->resize(3 * static_cast<std::size_t>(n));
  double* y = scratch->data();
  // y = P b (row i of b goes to row P(i)), as solve() starts
  const bool permuted = m_P.size() > 0;
  for (int i = 0; i < n; ++i) {
    const int r = permuted ? m_P.indices()[i] : i;
    for (int c = 0; c < 3; ++c) y[3 * r + c] = b[3 * i + c];
  }
  const int* lp = m_matrix.outerIndexPtr();
  const int* li = m_matrix.innerIndexPtr();
  const double* lx = m_matrix.valuePtr();
  // L y = y, column by column (the diagonal first in each): Eigen's lower column-major solve, which leaves a
  // column whose entry is zero alone (so the sign of a zero comes out as it does there)
  for (int j = 0; j < n; ++j) {
    double* yj = y + 3 * j;
    const bool nz[3] = {yj[0] != 0.0, yj[1] != 0.0, yj[2] != 0.0};
    if (!(nz[0] || nz[1] || nz[2])) continue;
    const double ljj = lx[lp[j]];
    for (int c = 0; c < 3; ++c)
      if (nz[c]) yj[c] /= ljj;
    const double t0 = yj[0], t1 = yj[1], t2 = yj[2];
    for (int p = lp[j] + 1; p < lp[j + 1]; ++p) {
      double* yi = y + 3 * li[p];
      const double v = lx[p];
      if (nz[0]) yi[0] -= t0 * v;
      if (nz[1]) yi[1] -= t1 * v;
      if (nz[2]) yi[2] -= t2 * v;
    }
  }
  // L^T y = y, from the last row up: Eigen's upper row-major solve of L's adjoint
  for (int i = n - 1; i >= 0; --i) {
    double t0 = y[3 * i], t1 = y[3 * i + 1], t2 = y[3 * i + 2];
    for (int p = lp[i] + 1; p < lp[i + 1]; ++p) {
      const double* yj = y + 3 * li[p];
      const double v = lx[p];
      t0 -= v * yj[0];
      t1 -= v * yj[1];
      t2 -= v * yj[2];
    }
    const double lii = lx[lp[i]];
    y[3 * i] = t0 / lii;
    y[3 * i + 1] = t1 / lii;
    y[3 * i + 2] = t2 / lii;
  }
  // x = P^-1 y
  for (int i = 0; i < n; ++i) {
    const int r = permuted ? m_P.indices()[i] : i;
    for (int c = 0; c < 3; ++c) x[3 * i + c] = y[3 * r + c];
  }
}

bool DowndatableLLT::downdate(const DowndateColumn* cols, int count) {
  const auto n = static_cast<std::size_t>(m_matrix.cols());
  if (on_path_.size() != n) {
    on_path_.assign(n, 0);
    w_.assign(n * kBatch, 0.0);
  }
  for (int first = 0; first < count; first += kBatch)
    if (!downdate_batch(cols + first, std::min(kBatch, count - first))) return false;
  return true;
}

bool DowndatableLLT::downdate_batch(const DowndateColumn* cols, int count) {
  // W = P V in the factor's numbering; then, column by column up the union of the columns' elimination-tree paths,
  // for each of them in order the hyperbolic rotation that takes w_t out of L L^T (L_kk' = sqrt(L_kk^2 - w_tk^2),
  // c = L_kk'/L_kk, s = w_tk/L_kk, L_ik' = (L_ik - s w_ti)/c, w_ti' = c w_ti - s L_ik'); w_t's entries stay within
  // its own path's columns, so a column off its path has w_tk = 0 and is left alone by it
  const int n = static_cast<int>(m_matrix.cols());
  double* w = w_.data();
  uint8_t* on_path = on_path_.data();
  int lowest = n;
  for (int t = 0; t < count; ++t) {
    int k = n;
    for (int e = 0; e < cols[t].count; ++e) {
      const int r = m_P.size() > 0 ? m_P.indices()[cols[t].rows[e]] : cols[t].rows[e];
      w[static_cast<std::size_t>(r) * kBatch + t] += cols[t].vals[e];
      k = std::min(k, r);
    }
    if (k == n) continue;
    lowest = std::min(lowest, k);
    for (; k >= 0 && !on_path[k]; k = m_parent[k]) on_path[k] = 1;
  }
  const int* lp = m_matrix.outerIndexPtr();
  const int* li = m_matrix.innerIndexPtr();
  double* lx = m_matrix.valuePtr();
  struct Rotation {
    int t;
    double c, s, ic;
  };
  Rotation rot[kBatch];
  bool ok = true;
  // a parent's number is above its children's: ascending order visits each path from the bottom
  for (int k = lowest; k < n; ++k) {
    if (!on_path[k]) continue;
    on_path[k] = 0;
    double* wk = w + static_cast<std::size_t>(k) * kBatch;
    double lkk = lx[lp[k]];
    int rotations = 0;
    for (int t = 0; t < count; ++t) {
      const double wtk = wk[t];
      wk[t] = 0.0;
      if (wtk == 0.0 || !ok) continue;
      const double r2 = lkk * lkk - wtk * wtk;
      if (!(r2 > 0.0)) {
        ok = false;  // keep walking to leave W zero
        continue;
      }
      const double r = std::sqrt(r2);
      rot[rotations++] = {t, r / lkk, wtk / lkk, lkk / r};
      lkk = r;
    }
    if (!ok || rotations == 0) continue;
    lx[lp[k]] = lkk;
    // four entries at a time: each entry's rotations are a chain of dependent operations, four chains overlap
    // (distinct rows, so distinct rows of W)
    const int end = lp[k + 1];
    int p = lp[k] + 1;
    for (; p + 4 <= end; p += 4) {
      double* w0 = w + static_cast<std::size_t>(li[p]) * kBatch;
      double* w1 = w + static_cast<std::size_t>(li[p + 1]) * kBatch;
      double* w2 = w + static_cast<std::size_t>(li[p + 2]) * kBatch;
      double* w3 = w + static_cast<std::size_t>(li[p + 3]) * kBatch;
      double x0 = lx[p], x1 = lx[p + 1], x2 = lx[p + 2], x3 = lx[p + 3];
      for (int q = 0; q < rotations; ++q) {
        const Rotation& g = rot[q];
        const double a0 = w0[g.t], a1 = w1[g.t], a2 = w2[g.t], a3 = w3[g.t];
        x0 = (x0 - g.s * a0) * g.ic;
        x1 = (x1 - g.s * a1) * g.ic;
        x2 = (x2 - g.s * a2) * g.ic;
        x3 = (x3 - g.s * a3) * g.ic;
        w0[g.t] = g.c * a0 - g.s * x0;
        w1[g.t] = g.c * a1 - g.s * x1;
        w2[g.t] = g.c * a2 - g.s * x2;
        w3[g.t] = g.c * a3 - g.s * x3;
      }
      lx[p] = x0;
      lx[p + 1] = x1;
      lx[p + 2] = x2;
      lx[p + 3] = x3;
    }
    for (; p < end; ++p) {
      double* wi = w + static_cast<std::size_t>(li[p]) * kBatch;
      double x = lx[p];
      for (int q = 0; q < rotations; ++q) {
        const Rotation& g = rot[q];
        x = (x - g.s * wi[g.t]) * g.ic;
        wi[g.t] = g.c * wi[g.t] - g.s * x;
      }
      lx[p] = x;
    }
  }
  return ok;
}

double DowndatableLLT::factor_work() const {
  const int* lp = m_matrix.outerIndexPtr();
  double work = 0.0;
  for (Eigen::Index k = 0; k < m_matrix.cols(); ++k) {
    const double c = lp[k + 1] - lp[k];
    work += c * c;
  }
  return work;
}

double DowndatableLLT::downdate_work(int a, int b) const {
  auto perm = [&](int r) { return r < 0 ? -1 : m_P.size() > 0 ? m_P.indices()[r] : r; };
  const int pa = perm(a), pb = perm(b);
  const int* lp = m_matrix.outerIndexPtr();
  double work = 0.0;
  for (int k = pa < 0 ? pb : pb < 0 ? pa : std::min(pa, pb); k >= 0; k = m_parent[k]) work += lp[k + 1] - lp[k];
  return work;
}

bool LocalGlobalSolver::fill_values(const Lattice& lat, double h_s) {
  // A = M / h^2 + (c / h) L_1 + sum_s k_s L_s written into the analysed pattern; false when an entry is not in it
  double* v = a_.valuePtr();
  std::fill(v, v + a_.nonZeros(), 0.0);
  auto add = [&](int r, int c, double x) {
    const int32_t k = value_index(a_, r, c);
    if (k < 0) return false;
    v[k] += x;
    return true;
  };
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (idx_[i] >= 0 && !add(idx_[i], idx_[i], lat.mass_kg[i] / (h_s * h_s))) return false;
  for (const Spring& s : lat.springs) {
    const double w = s.k_N_per_m + lat.damping_Ns_per_m / h_s;
    const int a = idx_[s.a], b = idx_[s.b];
    if (a >= 0 && !add(a, a, w)) return false;
    if (b >= 0 && !add(b, b, w)) return false;
    if (a >= 0 && b >= 0 && !(add(a, b, -w) && add(b, a, -w))) return false;
  }
  return true;
}

bool LocalGlobalSolver::prepare(const Lattice& lat, double h_s) {
  const std::size_t n = lat.num_nodes();
  // free-node numbering, noting whether it is the one the pattern was built for
  bool same_nodes = analysed_ && idx_.size() == n;
  idx_.resize(n);
  int nf = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const int32_t id = lat.fixed[i] ? -1 : nf++;
    same_nodes = same_nodes && idx_[i] == id;
    idx_[i] = id;
  }
  // numeric refactorisation in the analysed pattern (same nodes, no new spring: a new step size or a cut), else
  // assemble a new pattern and analyse it unless it equals the old one (a region of the same shape)
  if (!same_nodes || !fill_values(lat, h_s)) {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(n + 4 * lat.springs.size());
    for (std::size_t i = 0; i < n; ++i)
      if (idx_[i] >= 0) t.emplace_back(idx_[i], idx_[i], lat.mass_kg[i] / (h_s * h_s));
    for (const Spring& s : lat.springs) {
      const double w = s.k_N_per_m + lat.damping_Ns_per_m / h_s;
      const int a = idx_[s.a], b = idx_[s.b];
      if (a >= 0) t.emplace_back(a, a, w);
      if (b >= 0) t.emplace_back(b, b, w);
      if (a >= 0 && b >= 0) {
        t.emplace_back(a, b, -w);
        t.emplace_back(b, a, -w);
      }
    }
    SpMat m(nf, nf);
    m.setFromTriplets(t.begin(), t.end());
    m.makeCompressed();
    const bool same_pattern = analysed_ && m.rows() == a_.rows() && m.nonZeros() == a_.nonZeros() &&
                              std::equal(m.outerIndexPtr(), m.outerIndexPtr() + nf + 1, a_.outerIndexPtr()) &&
                              std::equal(m.innerIndexPtr(), m.innerIndexPtr() + m.nonZeros(), a_.innerIndexPtr());
    a_ = std::move(m);
    if (!same_pattern) {
      llt_.analyzePattern(a_);
      ++analyses_;
      analysed_ = true;
    }
  }
  llt_.factorize(a_);
  ++factorizations_;
  revision_ = lat.revision;
  h_s_ = h_s;
  b0_.resize(nf, 3);
  b_.resize(nf, 3);
  x_.resize(nf, 3);
  ok_ = llt_.info() == Eigen::Success;
  if (ok_) remember(lat);
  return ok_;
}

void LocalGlobalSolver::remember(const Lattice& lat) {
  springs_ = lat.springs;
  mass_ = lat.mass_kg;
  damping_ = lat.damping_Ns_per_m;
}

bool LocalGlobalSolver::downdate_removed(const Lattice& lat, double h_s) {
  // only when the factored lattice lost springs and nothing else that enters the matrix changed
  if (!ok_ || h_s != h_s_ || idx_.size() != lat.num_nodes() || lat.springs.size() >= springs_.size() ||
      springs_.size() - lat.springs.size() > static_cast<std::size_t>(max_downdates_) ||
      lat.damping_Ns_per_m != damping_ || lat.mass_kg != mass_)
    return false;
  for (std::size_t i = 0; i < idx_.size(); ++i)
    if ((idx_[i] < 0) != lat.fixed[i]) return false;
  // the remaining springs must be the old ones in order (cut_springs erases, keeping the order): a merge walk
  auto same = [](const Spring& x, const Spring& y) { return x.a == y.a && x.b == y.b && x.k_N_per_m == y.k_N_per_m; };
  std::size_t j = 0;
  for (const Spring& s : lat.springs) {
    while (j < springs_.size() && !same(springs_[j], s)) ++j;
    if (j == springs_.size()) return false;
    ++j;
  }
  removed_.clear();
  j = 0;
  for (std::size_t k = 0; k < springs_.size(); ++k) {
    if (j < lat.springs.size() && same(springs_[k], lat.springs[j])) ++j;
    else removed_.push_back(static_cast<int32_t>(k));
  }
  // downdates only while they are cheaper than a numeric refactorisation (a long stroke in one frame is not)
  double work = 0.0;
  for (int32_t k : removed_) work += llt_.downdate_work(idx_[springs_[k].a], idx_[springs_[k].b]);
  if (work > kDowndateWorkRatio * llt_.factor_work()) return false;
  cols_.clear();
  for (int32_t k : removed_) {
    const Spring& old = springs_[k];
    const double root_w = std::sqrt(old.k_N_per_m + damping_ / h_s);
    DowndateColumn c;
    if (idx_[old.a] >= 0) {
      c.rows[c.count] = idx_[old.a];
      c.vals[c.count++] = root_w;
    }
    if (idx_[old.b] >= 0) {
      c.rows[c.count] = idx_[old.b];
      c.vals[c.count++] = -root_w;
    }
    if (c.count > 0) cols_.push_back(c);
  }
  if (!llt_.downdate(cols_.data(), static_cast<int>(cols_.size()))) {
    ok_ = false;
    return false;
  }
  downdates_ += static_cast<int64_t>(cols_.size());
  springs_ = lat.springs;
  revision_ = lat.revision;
  return true;
}

bool LocalGlobalSolver::ready(const Lattice& lat, double h_s) {
  if (lat.revision != revision_ || h_s != h_s_ || idx_.size() != lat.num_nodes())
    if (!downdate_removed(lat, h_s)) prepare(lat, h_s);
  return ok_;
}

int LocalGlobalSolver::step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int iterations) {
  // the constant matrix holds springs only: a lattice with cell volume terms (scenes refuse the pairing) is
  // reported as a failed solve, so the step falls back to symplectic Euler instead of dropping the term
  if (lat->volume_Pa != 0.0 || lat->neo_mu_Pa != 0.0 || !lat->held_dof.empty()) return -1;
  if (!ready(*lat, h_s)) return -1;
  const std::size_t n = lat->num_nodes();
  const double inv_h2 = 1.0 / (h_s * h_s), c_h = lat->damping_Ns_per_m / h_s;
  // constant part of the rhs: M y / h^2 with the inertial target y = x + h v + h^2 M^-1 f_ext,
  // the damping term D x_n / h, and the couplings to fixed nodes moved across
  for (std::size_t i = 0; i < n; ++i) {
    if (idx_[i] < 0) continue;
    Vec3 f = lat->mass_kg[i] * lat->gravity_m_per_s2;
    if (!f_ext_N.empty()) f += f_ext_N[i];
    const Vec3 y = lat->x_m[i] + h_s * lat->v_m_per_s[i] + (h_s * h_s / lat->mass_kg[i]) * f;
    b0_.row(idx_[i]) = (lat->mass_kg[i] * inv_h2) * y.transpose();
    x_.row(idx_[i]) = lat->x_m[i].transpose();  // initial guess: where the node is (y is far off for stiff springs)
  }
  for (const Spring& s : lat->springs) {
    const int a = idx_[s.a], b = idx_[s.b];
    const Vec3 dx = lat->x_m[s.a] - lat->x_m[s.b];
    if (a >= 0) b0_.row(a) += c_h * dx.transpose();
    if (b >= 0) b0_.row(b) -= c_h * dx.transpose();
    const double w = s.k_N_per_m + c_h;
    if (a >= 0 && b < 0) b0_.row(a) += w * lat->x_m[s.b].transpose();
    if (b >= 0 && a < 0) b0_.row(b) += w * lat->x_m[s.a].transpose();
  }
  const int iters = std::max(1, iterations);
  auto pos = [&](int32_t node) -> Vec3 { return idx_[node] >= 0 ? Vec3(x_.row(idx_[node]).transpose()) : lat->x_m[node]; };
  for (int it = 0; it < iters; ++it) {
    // local: the nearest spring vector of rest length; global: one solve for the three coordinates
    b_ = b0_;
    for (const Spring& s : lat->springs) {
      const Vec3 d = pos(s.b) - pos(s.a);
      const double len = d.norm();
      const Vec3 target = len > 1e-12 * s.rest_m && len > 0.0 ? Vec3(d * (s.rest_m / len))
                                                              : Vec3(lat->rest_m[s.b] - lat->rest_m[s.a]);
      const int a = idx_[s.a], b = idx_[s.b];
      if (a >= 0) b_.row(a) -= s.k_N_per_m * target.transpose();
      if (b >= 0) b_.row(b) += s.k_N_per_m * target.transpose();
    }
    llt_.solve_rows3(b_.data(), x_.data(), &solve_scratch_);
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (idx_[i] < 0) continue;
    const Vec3 x = x_.row(idx_[i]).transpose();
    lat->v_m_per_s[i] = (x - lat->x_m[i]) / h_s;
    lat->x_m[i] = x;
  }
  return iters;
}

}  // namespace palpate
