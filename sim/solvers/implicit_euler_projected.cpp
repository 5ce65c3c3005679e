// ImplicitEulerSolver::projected_step: the backward Euler substep as the minimum of its incremental potential, by
// Newton steps on a positive semi-definite tangent with a backtracking line search (sim/solvers/implicit_euler.h).
#include <algorithm>
#include <cmath>

#include "core/clock.h"
#include "sim/lattice/forces.h"
#include "sim/lattice/hanging.h"
#include "sim/solvers/implicit_euler.h"

namespace palpate {
namespace {

// Halvings of a Newton step before the line search gives up (the potential cannot be lowered along it any more
// than round-off shows: the substep is as converged as it can be)
constexpr int kMaxHalvings = 30;
// Armijo's sufficient decrease: a step of length alpha must lower the potential by this share of alpha times its slope
constexpr double kArmijo = 1e-4;

}  // namespace

double ImplicitEulerSolver::incremental_potential(const Lattice& lat, double h_s, const std::vector<Vec3>& v,
                                                  const std::vector<Vec3>& f_ext_N) {
  const std::size_t n = lat.num_nodes();
  double e = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    trial_x_[i] = lat.fixed[i] ? x0_m_[i] : Vec3(x0_m_[i] + h_s * v[i]);
    if (lat.fixed[i]) continue;
    Vec3 load = lat.mass_kg[i] * lat.gravity_m_per_s2;
    if (!f_ext_N.empty()) load += f_ext_N[i];
    e += 0.5 * lat.mass_kg[i] * (v[i] - v0_m_per_s_[i]).squaredNorm() - h_s * load.dot(v[i]);
  }
  const double c = lat.damping_Ns_per_m;
  if (c != 0.0)
    for (const Spring& s : lat.springs) e += 0.5 * h_s * c * (v[s.b] - v[s.a]).squaredNorm();
  return e + elastic_energy_J(lat, trial_x_);
}

int ImplicitEulerSolver::projected_step(Lattice* lat, double h_s, const std::vector<Vec3>& f_ext_N, int max_iterations,
                                        int64_t deadline_ns, bool* out_of_time) {
  begin_step(lat);
  const std::size_t n = lat->num_nodes();
  const double tol_m_per_s = 1e-6 * lat->cell_m / h_s;
  double phi = incremental_potential(*lat, h_s, v_m_per_s_, f_ext_N);
  if (!std::isfinite(phi)) return -1;
  projected_ = true;
  int it = 0;
  step_cg_iterations_ = 0;
  while (it < std::max(1, max_iterations)) {
    // past the deadline the step keeps the last iterate (each accepted one lowered the potential)
    if (it > 0 && deadline_ns > 0 && monotonic_ns() > deadline_ns) {
      if (out_of_time) *out_of_time = true;
      break;
    }
    residual(*lat, h_s, f_ext_N);
    assemble(*lat, h_s, x_m_);
    std::fill(delta_.begin(), delta_.end(), Vec3::Zero());
    if (!solve(*lat)) {  // J is positive definite here: only a non-finite residual fails
      projected_ = false;
      return -1;
    }
    ++it;
    step_cg_iterations_ += last_cg_iterations_;
    double slope = 0.0;  // d phi along delta: -g . delta < 0, delta solving J delta = -g with J positive definite
    for (std::size_t i = 0; i < n; ++i) slope -= rhs_[i].dot(delta_[i]);
    spread_hanging(*lat, &delta_);
    double alpha = 1.0, trial = phi;
    bool lowered = false;
    for (int halving = 0; halving <= kMaxHalvings && !lowered; ++halving, alpha *= 0.5) {
      for (std::size_t i = 0; i < n; ++i) trial_v_[i] = lat->fixed[i] ? v_m_per_s_[i] : Vec3(v_m_per_s_[i] + alpha * delta_[i]);
      trial = incremental_potential(*lat, h_s, trial_v_, f_ext_N);
      lowered = std::isfinite(trial) && trial <= phi + kArmijo * alpha * slope;
      if (lowered) break;
    }
    if (!lowered) break;  // nothing lower along the Newton step: converged as far as round-off shows
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      if (!lat->fixed[i]) worst = std::max(worst, (trial_v_[i] - v_m_per_s_[i]).cwiseAbs().maxCoeff());
    std::swap(v_m_per_s_, trial_v_);
    phi = trial;
    if (!(worst > tol_m_per_s)) break;
  }
  projected_ = false;
  finish_step(lat, h_s);
  return it;
}

}  // namespace palpate
