#include "sim/solvers/implicit_euler.h"

#include <algorithm>
#include <cmath>

#include "sim/lattice/forces.h"
#include "sim/lattice/hanging.h"
#include "sim/material/volume_term.h"

namespace palpate {
namespace {

// Most conjugate gradient iterations per Newton solve: J's condition number is bounded independently of the
// lattice size, so a converging solve needs tens; the cap only stops a pathological one.
constexpr int kMaxCgIterations = 1000;

double dot(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i].dot(b[i]);
  return s;
}

}  // namespace

void ImplicitEulerSolver::prepare(const Lattice& lat) {
  const std::size_t n = lat.num_nodes();
  spring_block_.resize(lat.springs.size());
  node_block_.resize(n);
  node_block_inv_.resize(n);
  for (auto* v : {&rhs_, &r_, &z_, &p_, &jp_}) v->assign(n, Vec3::Zero());
  delta_.assign(n, Vec3::Zero());
  last_dv_m_per_s_.assign(n, Vec3::Zero());  // no previous step to start from
  x0_m_.resize(n);
  v0_m_per_s_.resize(n);
  trial_v_.resize(n);
  trial_x_.resize(n);
  x_m_.resize(n);
  v_m_per_s_.resize(n);
  f_N_.resize(n);
  revision_ = lat.revision;
  num_springs_ = lat.springs.size();
}

void ImplicitEulerSolver::assemble(const Lattice& lat, double h_s, const std::vector<Vec3>& x_m) {
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) node_block_[i] = lat.mass_kg[i] * Mat3::Identity();
  const Mat3 damping = h_s * lat.damping_Ns_per_m * Mat3::Identity();
  for (std::size_t k = 0; k < lat.springs.size(); ++k) {
    const Spring& s = lat.springs[k];
    const Mat3 b = damping + h_s * h_s * spring_stiffness_block(s, x_m[s.b] - x_m[s.a], true);
    spring_block_[k] = b;
    node_block_[s.a] += b;
    node_block_[s.b] += b;
  }
  // the cells' volume terms: h^2 lambda_v l^3 c_a c_b^T (Gauss-Newton: the (J - 1) d^2 J part is left out)
  if (lat.volume_Pa != 0.0) {
    volume_gradients(lat, x_m, &cell_c_, &cell_w_);
    for (std::size_t k = 0; k < cell_c_.size(); ++k) {
      cell_w_[k] *= h_s * h_s;
      for (int a = 0; a < 8; ++a) {
        const Vec3& c = cell_c_[k][static_cast<std::size_t>(a)];
        node_block_[static_cast<std::size_t>(lat.cell_nodes[k][a])] += cell_w_[k] * c * c.transpose();
      }
    }
  } else {
    cell_c_.clear();
  }
  // the cells' Neo-Hookean terms: h^2 times their tangent blocks
  neo_h2_ = h_s * h_s;
  if (projected_ && lat.neo_mu_Pa != 0.0) {
    neo_.clear();
    neo_h9_.resize(lat.cell_nodes.size());
    for (std::size_t k = 0; k < neo_h9_.size(); ++k) {
      const double l = lat.cell_edge_m(k);
      const auto& nodes = lat.cell_nodes[k];
      neo_h9_[k] = (l * l * l) * neo_hookean_projected_hessian(lat.neo_mu_Pa, lat.neo_lambda_Pa,
                                                               cell_deformation_gradient(x_m, nodes, l));
      // corner a's diagonal block: sum over j, j' of g_j g_j' H(r + 3 j, s + 3 j')
      for (int a = 0; a < 8; ++a) {
        const Vec3 g = corner_gradient(a, l);
        Mat3 b = Mat3::Zero();
        for (int j = 0; j < 3; ++j)
          for (int jj = 0; jj < 3; ++jj) b += (g[j] * g[jj]) * neo_h9_[k].block<3, 3>(3 * j, 3 * jj);
        node_block_[static_cast<std::size_t>(nodes[a])] += neo_h2_ * b;
      }
    }
  } else if (lat.neo_mu_Pa != 0.0) {
    neo_h9_.clear();
    neo_hookean_cells(lat, x_m, &neo_);
    for (std::size_t k = 0; k < neo_.size(); ++k)
      for (int a = 0; a < 8; ++a)
        node_block_[static_cast<std::size_t>(lat.cell_nodes[k][a])] += neo_h2_ * neo_hookean_block(lat, neo_[k], a, a);
  } else {
    neo_.clear();
    neo_h9_.clear();
  }
  // a refined lattice: a hanging node's block moves to its masters (the diagonal of P^T J P, less the coupling
  // between masters), finest first so a hanging master passes its share on
  for (auto h = lat.hanging.rbegin(); h != lat.hanging.rend(); ++h)
    for (int k = 0; k < h->count; ++k) {
      const auto m = static_cast<std::size_t>(h->master[static_cast<std::size_t>(k)]);
      const double w = h->weight[static_cast<std::size_t>(k)];
      node_block_[m] += w * w * node_block_[static_cast<std::size_t>(h->node)];
    }
  // block-Jacobi preconditioner: each free node's 3x3 diagonal block inverted (symmetric positive definite)
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    node_block_inv_[i] = lat.fixed[i] ? Mat3::Zero() : Mat3(node_block_[i].inverse());
  for (const HangingNode& hn : lat.hanging) node_block_inv_[static_cast<std::size_t>(hn.node)] = Mat3::Zero();
  // held DOFs: the block restricted to the free axes, inverted
  for (std::size_t i = 0; 3 * i < lat.held_dof.size(); ++i) {
    const uint8_t* held = &lat.held_dof[3 * i];
    if (lat.fixed[i] || !(held[0] || held[1] || held[2])) continue;
    Mat3 b = node_block_[i];
    for (int a = 0; a < 3; ++a)
      if (held[a]) b.row(a).setZero(), b.col(a).setZero(), b(a, a) = 1.0;
    node_block_inv_[i] = b.inverse();
    for (int a = 0; a < 3; ++a)
      if (held[a]) node_block_inv_[i].row(a).setZero(), node_block_inv_[i].col(a).setZero();
  }
}

void ImplicitEulerSolver::multiply(const Lattice& lat, const std::vector<Vec3>& p_free, std::vector<Vec3>* out) const {
  // J p = M p + sum_s B_s (p_a - p_b) on a and its negative on b; p is zero at fixed nodes, so rows of fixed nodes
  // are dropped at the end and columns need no test. A refined lattice's product is P^T J P: the hanging nodes'
  // entries spread from their masters first, their rows folded back onto the masters last.
  if (!lat.hanging.empty()) {
    p_spread_ = p_free;
    spread_hanging(lat, &p_spread_);
  }
  const std::vector<Vec3>& p = lat.hanging.empty() ? p_free : p_spread_;
  std::vector<Vec3>& y = *out;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) y[i] = lat.mass_kg[i] * p[i];
  for (std::size_t k = 0; k < lat.springs.size(); ++k) {
    const Spring& s = lat.springs[k];
    const Vec3 d = spring_block_[k] * (p[s.a] - p[s.b]);
    y[s.a] += d;
    y[s.b] -= d;
  }
  for (std::size_t k = 0; k < cell_c_.size(); ++k) {
    // the cell's rank-one block: w c (c . p)
    const auto& nodes = lat.cell_nodes[k];
    const auto& c = cell_c_[k];
    double dot_cp = 0.0;
    for (int a = 0; a < 8; ++a) dot_cp += c[static_cast<std::size_t>(a)].dot(p[static_cast<std::size_t>(nodes[a])]);
    dot_cp *= cell_w_[k];
    for (int a = 0; a < 8; ++a) y[static_cast<std::size_t>(nodes[a])] += dot_cp * c[static_cast<std::size_t>(a)];
  }
  if (!neo_.empty()) {
    neo_y_.assign(lat.num_nodes(), Vec3::Zero());
    add_neo_hookean_product(lat, neo_, p, &neo_y_);
    for (std::size_t i = 0; i < lat.num_nodes(); ++i) y[i] += neo_h2_ * neo_y_[i];
  }
  for (std::size_t k = 0; k < neo_h9_.size(); ++k) {
    // the projected cell: dF = sum_a p_a g_a^T, dP = H vec dF, corner b gets h^2 dP g_b
    const auto& nodes = lat.cell_nodes[k];
    const double l = lat.cell_edge_m(k);
    Mat3 df = Mat3::Zero();
    for (int a = 0; a < 8; ++a) df += p[static_cast<std::size_t>(nodes[a])] * corner_gradient(a, l).transpose();
    Mat3 dp;
    Eigen::Map<Eigen::Matrix<double, 9, 1>>(dp.data()) = neo_h9_[k] * Eigen::Map<const Eigen::Matrix<double, 9, 1>>(df.data());
    dp *= neo_h2_;
    for (int b = 0; b < 8; ++b) y[static_cast<std::size_t>(nodes[b])] += dp * corner_gradient(b, l);
  }
  fold_hanging(lat, &y);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (lat.fixed[i]) y[i].setZero();
  for (std::size_t d = 0; d < lat.held_dof.size(); ++d)
    if (lat.held_dof[d]) y[d / 3][static_cast<int>(d % 3)] = 0.0;
}

bool ImplicitEulerSolver::solve(const Lattice& lat) {
  const std::size_t n = lat.num_nodes();
  const double b_norm = std::sqrt(dot(rhs_, rhs_));
  last_cg_iterations_ = 0;
  last_cg_residual_ = 0.0;
  if (!std::isfinite(b_norm)) return false;
  if (b_norm == 0.0) {
    std::fill(delta_.begin(), delta_.end(), Vec3::Zero());
    return true;
  }
  // start from the guess in delta_; from zero when that guess is worse than none
  multiply(lat, delta_, &jp_);
  for (std::size_t i = 0; i < n; ++i) r_[i] = rhs_[i] - jp_[i];
  double r_norm = std::sqrt(dot(r_, r_));
  if (!(r_norm < b_norm)) {
    std::fill(delta_.begin(), delta_.end(), Vec3::Zero());
    r_ = rhs_;
    r_norm = b_norm;
  }
  for (std::size_t i = 0; i < n; ++i) p_[i] = z_[i] = node_block_inv_[i] * r_[i];
  double rz = dot(r_, z_);
  const double target = kCgTolerance * b_norm;
  int it = 0;
  while (r_norm > target && it < kMaxCgIterations) {
    multiply(lat, p_, &jp_);
    const double curvature = dot(p_, jp_);
    if (!(curvature > 0.0)) return false;  // J is positive definite: this is a breakdown (or NaN)
    const double alpha = rz / curvature;
    for (std::size_t i = 0; i < n; ++i) {
      delta_[i] += alpha * p_[i];
      r_[i] -= alpha * jp_[i];
      z_[i] = node_block_inv_[i] * r_[i];
    }
    ++it;
    r_norm = std::sqrt(dot(r_, r_));
    const double rz_next = dot(r_, z_);
    const double beta = rz_next / rz;
    rz = rz_next;
    for (std::size_t i = 0; i < n; ++i) p_[i] = z_[i] + beta * p_[i];
  }
  last_cg_iterations_ = it;
  last_cg_residual_ = r_norm / b_norm;
  return std::isfinite(r_norm);
}

void ImplicitEulerSolver::residual(const Lattice& lat, double h_s, const std::vector<Vec3>& f_ext_N) {
  // residual g(v) = M (v - v0) - h f(x0 + h v, v); the Newton system is J delta = -g
  const std::size_t n = lat.num_nodes();
  for (std::size_t i = 0; i < n; ++i) x_m_[i] = lat.fixed[i] ? x0_m_[i] : Vec3(x0_m_[i] + h_s * v_m_per_s_[i]);
  compute_forces(lat, x_m_, v_m_per_s_, f_ext_N, &f_N_);
  for (std::size_t i = 0; i < n; ++i)
    rhs_[i] = lat.fixed[i] ? Vec3::Zero() : Vec3(h_s * f_N_[i] - lat.mass_kg[i] * (v_m_per_s_[i] - v0_m_per_s_[i]));
  if (!lat.hanging.empty()) {
    // the residual of the constrained lattice: P^T g (fixed masters and held DOFs take none)
    fold_hanging(lat, &rhs_);
    for (std::size_t i = 0; i < n; ++i)
      if (lat.fixed[i]) rhs_[i].setZero();
    for (std::size_t d = 0; d < lat.held_dof.size(); ++d)
      if (lat.held_dof[d]) rhs_[d / 3][static_cast<int>(d % 3)] = 0.0;
  }
}

void ImplicitEulerSolver::begin_step(Lattice* lat) {
  if (lat->revision != revision_ || node_block_.size() != lat->num_nodes() || num_springs_ != lat->springs.size())
    prepare(*lat);
  // a refined lattice's hanging nodes start where their faces are (a state carried over or set by hand may not)
  spread_hanging(*lat, &lat->x_m);
  spread_hanging(*lat, &lat->v_m_per_s);
  std::copy(lat->x_m.begin(), lat->x_m.end(), x0_m_.begin());
  std::copy(lat->v_m_per_s.begin(), lat->v_m_per_s.end(), v0_m_per_s_.begin());
  std::copy(v0_m_per_s_.begin(), v0_m_per_s_.end(), v_m_per_s_.begin());
}

void ImplicitEulerSolver::finish_step(Lattice* lat, double h_s) {
  for (std::size_t i = 0; i < lat->num_nodes(); ++i) {
    if (lat->fixed[i]) continue;
    last_dv_m_per_s_[i] = v_m_per_s_[i] - v0_m_per_s_[i];
    lat->v_m_per_s[i] = v_m_per_s_[i];
    lat->x_m[i] = x0_m_[i] + h_s * v_m_per_s_[i];
  }
}

int ImplicitEulerSolver::step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int max_iterations) {
  begin_step(lat);
  const std::size_t n = lat->num_nodes();
  const double tol_m_per_s = 1e-9 * lat->cell_m / h_s;
  int it = 0;
  step_cg_iterations_ = 0;
  while (it < std::max(1, max_iterations)) {
    residual(*lat, h_s, f_ext_N);
    assemble(*lat, h_s, x_m_);
    // warm start: the first solve from the previous step's velocity change (accelerations change little between
    // steps), later Newton corrections from zero
    if (it == 0) std::copy(last_dv_m_per_s_.begin(), last_dv_m_per_s_.end(), delta_.begin());
    else std::fill(delta_.begin(), delta_.end(), Vec3::Zero());
    if (!solve(*lat)) {
      std::fill(last_dv_m_per_s_.begin(), last_dv_m_per_s_.end(), Vec3::Zero());  // no warm start from a broken solve
      return -1;
    }
    ++it;
    step_cg_iterations_ += last_cg_iterations_;
    spread_hanging(*lat, &delta_);
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      if (!lat->fixed[i]) {
        v_m_per_s_[i] += delta_[i];
        worst = std::max(worst, delta_[i].cwiseAbs().maxCoeff());
      }
    if (!(worst > tol_m_per_s)) break;  // converged (or non-finite: the caller's check catches it)
  }
  finish_step(lat, h_s);
  return it;
}

}  // namespace palpate
