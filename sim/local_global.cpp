#include "sim/local_global.h"

namespace palpate {

bool LocalGlobalSolver::prepare(const Lattice& lat, double h_s) {
  const std::size_t n = lat.num_nodes();
  idx_.assign(n, -1);
  int nf = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!lat.fixed[i]) idx_[i] = nf++;
  // A = M / h^2 + (c / h) L_1 + sum_s k_s L_s over the free nodes (graph Laplacians of the springs)
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
  llt_.compute(m);
  ++factorizations_;
  revision_ = lat.revision;
  h_s_ = h_s;
  b0_.resize(nf, 3);
  b_.resize(nf, 3);
  x_.resize(nf, 3);
  ok_ = llt_.info() == Eigen::Success;
  return ok_;
}

int LocalGlobalSolver::step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int iterations) {
  if (lat->revision != revision_ || h_s != h_s_ || idx_.size() != lat->num_nodes()) prepare(*lat, h_s);
  if (!ok_) return -1;
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
    x_ = llt_.solve(b_);
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
