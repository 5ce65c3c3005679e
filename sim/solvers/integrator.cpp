#include "sim/solvers/integrator.h"

#include <algorithm>
#include <cmath>

#include "core/clock.h"
#include "sim/lattice/forces.h"
#include "sim/lattice/hanging.h"
#include "sim/solvers/implicit_euler.h"
#include "sim/solvers/local_global.h"
#include "sim/solvers/strain_limit.h"

namespace palpate {
namespace {

constexpr int kDefaultNewtonIterations = 1;
constexpr int kStrainLimitSweeps = 4;
// Most pieces a failed implicit substep is split into before the explicit fallback: J = M + h D + h^2 K is positive
// definite once h^2 times K's most negative curvature is under the mass, so a squashed or inverted Neo-Hookean cell
// whose tangent broke the solve at the frame's step is stepped at a quarter, an eighth... of it
constexpr int kMaxImplicitSplit = 64;
// Most Newton steps of the projected step that takes a substep no split could (ImplicitEulerSolver::projected_step)
constexpr int kProjectedNewtonIterations = 20;

// What implicit_split and implicit_substep return when the step's deadline passed in their retries
constexpr int kOutOfTime = -2;

bool past(const StepOptions& opts) { return opts.deadline_ns > 0 && monotonic_ns() > opts.deadline_ns; }

// An implicit Euler substep h taken again in 2, 4, ... kMaxImplicitSplit pieces after the whole one failed (the
// solver leaves the lattice as it was): the iterations, or -1 when every split failed, or kOutOfTime when the deadline
// passed first (either way the lattice back where it was)
int implicit_split(Lattice* lat, double h, const std::vector<Vec3>& f_ext, int newton, const StepOptions& opts,
                   IntegratorWorkspace* ws, int* cg_iterations) {
  ws->x0_m = lat->x_m;
  ws->v0_m_per_s = lat->v_m_per_s;
  for (int split = 2; split <= kMaxImplicitSplit; split *= 2) {
    int total = 0;
    bool ok = true;
    for (int k = 0; k < split && ok; ++k) {
      if (past(opts)) {
        lat->x_m = ws->x0_m;
        lat->v_m_per_s = ws->v0_m_per_s;
        return kOutOfTime;
      }
      const int it = ws->implicit->step(lat, h / split, f_ext, newton);
      *cg_iterations += ws->implicit->step_cg_iterations();
      ok = it >= 0;
      total += std::max(it, 0);
    }
    if (ok) return total;
    lat->x_m = ws->x0_m;
    lat->v_m_per_s = ws->v0_m_per_s;
  }
  return -1;
}

// Whether a step may leave the lattice here: finite, and no spring stretched past kDivergedStrain (where the caller
// would reset it)
bool sound(const Lattice& lat) {
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (!lat.x_m[i].allFinite() || !lat.v_m_per_s[i].allFinite()) return false;
  return max_strain(lat) <= kDivergedStrain;
}

// One implicit Euler substep: the Newton step(s) of ImplicitEulerSolver::step; when its solve breaks down, the substep
// in 2, 4, ... pieces; when every split breaks down too, or the step solved but landed where the lattice would be
// reset (its linearisation far from the material's answer, as at a cell squashed past its tangent's reach), the
// substep again from its start by projected Newton: the minimum of its potential, on a tangent kept positive. The
// iterations, or -1 when that failed too (the lattice back at the substep's start). Past opts.deadline_ns the retries
// are cut short (kOutOfTime): the splits stop, and projected Newton takes its first step and then stops, the lattice
// keeping that iterate (every accepted step lowers the substep's incremental potential).
int implicit_substep(Lattice* lat, double h, const std::vector<Vec3>& f_ext, const StepOptions& opts,
                     IntegratorWorkspace* ws, StepReport* rep) {
  if (!ws->implicit) ws->implicit = std::make_unique<ImplicitEulerSolver>();
  const int newton = opts.iterations > 0 ? opts.iterations : kDefaultNewtonIterations;
  ws->x0_m = lat->x_m;
  ws->v0_m_per_s = lat->v_m_per_s;
  int iters = ws->implicit->step(lat, h, f_ext, newton);
  rep->cg_iterations += ws->implicit->step_cg_iterations();
  if (iters < 0) {
    ++rep->implicit_splits;
    iters = implicit_split(lat, h, f_ext, newton, opts, ws, &rep->cg_iterations);  // from ws->x0_m, the same start
  }
  if (iters >= 0 && sound(*lat)) return iters;
  // (out of time in the splits, the lattice is back at the substep's start: projected Newton still takes its first
  // step, so the substep moves on, at the cost of one more solve)
  bool out_of_time = iters == kOutOfTime;
  lat->x_m = ws->x0_m;
  lat->v_m_per_s = ws->v0_m_per_s;
  iters = ws->implicit->projected_step(lat, h, f_ext, kProjectedNewtonIterations,
                                       past(opts) ? 1 : opts.deadline_ns, &out_of_time);
  rep->cg_iterations += ws->implicit->step_cg_iterations();
  if (iters >= 0) ++rep->projected_steps;
  return out_of_time && iters >= 0 ? kOutOfTime : iters;
}

// One explicit (eq. 8) or symplectic Euler substep.
void euler_substep(Lattice* lat, bool symplectic, double h, const std::vector<Vec3>& f_ext, IntegratorWorkspace* ws) {
  compute_forces(*lat, lat->x_m, lat->v_m_per_s, f_ext, &ws->f_N);
  // a refined lattice: the hanging nodes' forces act on their masters, and the hanging nodes follow them after
  // (each master's own mass only: a fallback, scenes step refined lattices with implicit Euler)
  fold_hanging(*lat, &ws->f_N);
  for (std::size_t i = 0; i < lat->num_nodes(); ++i) {
    if (lat->fixed[i]) continue;
    const Vec3 a = ws->f_N[i] / lat->mass_kg[i];
    if (!symplectic) {
      lat->x_m[i] += h * lat->v_m_per_s[i];  // eq. (8): position from the old velocity
      lat->v_m_per_s[i] += h * a;
    } else {
      lat->v_m_per_s[i] += h * a;            // symplectic: position from the new velocity
      lat->x_m[i] += h * lat->v_m_per_s[i];
    }
  }
  spread_hanging(*lat, &lat->x_m);
  spread_hanging(*lat, &lat->v_m_per_s);
}

// One classical Runge-Kutta substep of (x' = v, v' = M^-1 f(x, v)).
void rk4_substep(Lattice* lat, double h, const std::vector<Vec3>& f_ext, IntegratorWorkspace* ws) {
  const std::size_t n = lat->num_nodes();
  ws->x0_m = lat->x_m;
  ws->v0_m_per_s = lat->v_m_per_s;
  ws->stage_x = lat->x_m;
  ws->stage_v = lat->v_m_per_s;
  ws->acc_x.assign(n, Vec3::Zero());
  ws->acc_v.assign(n, Vec3::Zero());
  const double stage_step[4] = {0.5 * h, 0.5 * h, h, 0.0};
  const double weight[4] = {1.0, 2.0, 2.0, 1.0};
  for (int k = 0; k < 4; ++k) {
    compute_forces(*lat, ws->stage_x, ws->stage_v, f_ext, &ws->f_N);
    for (std::size_t i = 0; i < n; ++i) {
      if (lat->fixed[i]) continue;
      const Vec3 dx = ws->stage_v[i];
      const Vec3 dv = ws->f_N[i] / lat->mass_kg[i];
      ws->acc_x[i] += weight[k] * dx;
      ws->acc_v[i] += weight[k] * dv;
      ws->stage_x[i] = ws->x0_m[i] + stage_step[k] * dx;
      ws->stage_v[i] = ws->v0_m_per_s[i] + stage_step[k] * dv;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (lat->fixed[i]) continue;
    lat->x_m[i] = ws->x0_m[i] + (h / 6.0) * ws->acc_x[i];
    lat->v_m_per_s[i] = ws->v0_m_per_s[i] + (h / 6.0) * ws->acc_v[i];
  }
}

}  // namespace

IntegratorWorkspace::IntegratorWorkspace() = default;
IntegratorWorkspace::~IntegratorWorkspace() = default;
IntegratorWorkspace::IntegratorWorkspace(IntegratorWorkspace&&) noexcept = default;
IntegratorWorkspace& IntegratorWorkspace::operator=(IntegratorWorkspace&&) noexcept = default;

StepOptions step_options(const LatticeSpec& spec) {
  StepOptions o;
  o.kind = spec.integrator;
  o.substeps = spec.substeps;
  o.max_substeps = spec.max_substeps;
  o.iterations = spec.iterations;
  o.strain_limit = spec.strain_limit;
  return o;
}

namespace {

// Whether the scheme's substeps come from the stability bound (the others take 1 unless told).
bool automatic_substeps(const StepOptions& opts) {
  return opts.substeps <= 0 && (opts.kind == IntegratorKind::kSymplecticEuler || opts.kind == IntegratorKind::kRk4);
}

// Automatic substeps for dt_s given the symplectic Euler bound (safety 0.8).
int substeps_from_bound(const StabilityBound& bound, const StepOptions& opts, double dt_s) {
  // RK4's stability interval on the imaginary axis (2.83 / w) contains symplectic Euler's (2 / w): one bound serves
  const double h_max = bound.max_stable_dt_s;
  int steps = 1;
  if (std::isfinite(h_max) && h_max > 0.0) steps = static_cast<int>(std::min(std::ceil(dt_s / h_max), 1e9));
  else if (!(h_max > 0.0)) steps = opts.max_substeps;  // no stable step (or no bound): as many as allowed
  return std::clamp(steps, 1, std::max(1, opts.max_substeps));
}

}  // namespace

const StabilityBound& cached_stability_bound(const Lattice& lat, IntegratorWorkspace* ws) {
  if (ws->bound_revision != lat.revision || lat.revision == 0) {
    ws->bound = stability_bound(lat, 0.8);
    ws->bound_revision = lat.revision;
  }
  return ws->bound;
}

int substeps_for(const Lattice& lat, const StepOptions& opts, double dt_s) {
  if (!automatic_substeps(opts)) return std::max(1, opts.substeps);
  return substeps_from_bound(stability_bound(lat, 0.8), opts, dt_s);
}

int substeps_for(const Lattice& lat, const StepOptions& opts, double dt_s, IntegratorWorkspace* ws) {
  if (!automatic_substeps(opts)) return std::max(1, opts.substeps);
  return substeps_from_bound(cached_stability_bound(lat, ws), opts, dt_s);
}

StepReport step_lattice(Lattice* lat, const StepOptions& opts, double dt_s, const std::vector<Vec3>& f_ext_N,
                        IntegratorWorkspace* ws) {
  StepReport rep;
  const int steps = substeps_for(*lat, opts, dt_s, ws);
  const double h = dt_s / steps;
  for (int s = 0; s < steps; ++s) {
    int iters = 0;
    switch (opts.kind) {
      case IntegratorKind::kExplicitEuler: euler_substep(lat, false, h, f_ext_N, ws); break;
      case IntegratorKind::kSymplecticEuler: euler_substep(lat, true, h, f_ext_N, ws); break;
      case IntegratorKind::kRk4: rk4_substep(lat, h, f_ext_N, ws); break;
      case IntegratorKind::kImplicitEuler:
        iters = implicit_substep(lat, h, f_ext_N, opts, ws, &rep);
        break;
      case IntegratorKind::kLocalGlobal:
        if (!ws->local_global) ws->local_global = std::make_unique<LocalGlobalSolver>();
        iters = ws->local_global->step(lat, h, f_ext_N,
                                       opts.iterations > 0 ? opts.iterations : kDefaultLocalGlobalIterations);
        break;
    }
    if (iters == kOutOfTime) {
      // the frame's deadline passed while a failed substep was retried: the step ends here, the lattice where it got
      rep.out_of_time = true;
      rep.substeps = s + 1;
      break;
    }
    if (iters < 0) {
      // a failed solve: take the substep with a stable explicit scheme rather than stall
      rep.solver_ok = false;
      const double h_safe = cached_stability_bound(*lat, ws).max_stable_dt_s;
      const int sub = std::isfinite(h_safe) && h_safe > 0.0
                          ? std::clamp(static_cast<int>(std::ceil(h / h_safe)), 1, std::max(1, opts.max_substeps))
                          : 1;
      for (int k = 0; k < sub; ++k) euler_substep(lat, true, h / sub, f_ext_N, ws);
    } else {
      rep.iterations += iters;
    }
    if (opts.strain_limit > 0.0) limit_strain(lat, opts.strain_limit, kStrainLimitSweeps);
  }
  if (!rep.out_of_time) rep.substeps = steps;
  for (std::size_t i = 0; i < lat->num_nodes() && rep.finite; ++i)
    rep.finite = lat->x_m[i].allFinite() && lat->v_m_per_s[i].allFinite();
  rep.max_strain = rep.finite ? max_strain(*lat) : INFINITY;
  rep.diverged = !rep.finite || rep.max_strain > kDivergedStrain;
  return rep;
}

void prepare_step(const Lattice& lat, const StepOptions& opts, double dt_s, IntegratorWorkspace* ws) {
  if (opts.kind != IntegratorKind::kLocalGlobal) return;
  if (!ws->local_global) ws->local_global = std::make_unique<LocalGlobalSolver>();
  ws->local_global->ready(lat, dt_s / substeps_for(lat, opts, dt_s, ws));
}

StepReport step_lattice(Lattice* lat, IntegratorKind kind, double dt_s, int max_substeps,
                        const std::vector<Vec3>& f_ext_N, IntegratorWorkspace* ws) {
  StepOptions o;
  o.kind = kind;
  o.max_substeps = max_substeps;
  return step_lattice(lat, o, dt_s, f_ext_N, ws);
}

}  // namespace palpate
