#include "sim/integrator.h"

#include <algorithm>
#include <cmath>

#include "sim/forces.h"

namespace palpate {

StabilityBound stability_bound(const Lattice& lat, double safety) {
  const std::size_t n = lat.num_nodes();
  std::vector<double> ksum(n, 0.0), csum(n, 0.0);
  for (const Spring& s : lat.springs) {
    ksum[s.a] += s.k_N_per_m;
    ksum[s.b] += s.k_N_per_m;
    csum[s.a] += lat.damping_Ns_per_m;
    csum[s.b] += lat.damping_Ns_per_m;
  }
  double w2 = 0.0, g = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (lat.fixed[i]) continue;
    w2 = std::max(w2, 2.0 * ksum[i] / lat.mass_kg[i]);
    g = std::max(g, 2.0 * csum[i] / lat.mass_kg[i]);
  }
  StabilityBound b;
  b.omega_max_rad_per_s = std::sqrt(w2);
  b.damping_rate_per_s = g;
  // largest h with h^2 w2 + 2 h g <= 4 s (the symplectic Euler stability region of a damped oscillator)
  const double rhs = 4.0 * safety;
  if (w2 > 0.0) b.max_stable_dt_s = (-2.0 * g + std::sqrt(4.0 * g * g + 4.0 * w2 * rhs)) / (2.0 * w2);
  else if (g > 0.0) b.max_stable_dt_s = rhs / (2.0 * g);
  else b.max_stable_dt_s = INFINITY;
  return b;
}

StepReport step_lattice(Lattice* lat, IntegratorKind kind, double dt_s, int max_substeps,
                        const std::vector<Vec3>& f_ext_N, IntegratorWorkspace* ws) {
  StepReport rep;
  const std::size_t n = lat->num_nodes();
  int steps = 1;
  if (kind == IntegratorKind::kSymplecticEuler) {
    const double h_max = stability_bound(*lat, 0.8).max_stable_dt_s;
    if (std::isfinite(h_max) && h_max > 0.0) steps = static_cast<int>(std::ceil(dt_s / h_max));
    steps = std::clamp(steps, 1, std::max(1, max_substeps));
  }
  const double h = dt_s / steps;
  for (int s = 0; s < steps; ++s) {
    compute_forces(*lat, lat->x_m, lat->v_m_per_s, f_ext_N, &ws->f_N);
    for (std::size_t i = 0; i < n; ++i) {
      if (lat->fixed[i]) continue;
      const Vec3 a = ws->f_N[i] / lat->mass_kg[i];
      if (kind == IntegratorKind::kExplicitEuler) {
        lat->x_m[i] += h * lat->v_m_per_s[i];  // eq. (8): position from the old velocity
        lat->v_m_per_s[i] += h * a;
      } else {
        lat->v_m_per_s[i] += h * a;             // symplectic: position from the new velocity
        lat->x_m[i] += h * lat->v_m_per_s[i];
      }
    }
  }
  rep.substeps = steps;
  for (std::size_t i = 0; i < n && rep.finite; ++i)
    rep.finite = lat->x_m[i].allFinite() && lat->v_m_per_s[i].allFinite();
  return rep;
}

}  // namespace palpate
