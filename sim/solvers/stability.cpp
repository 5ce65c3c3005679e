#include "sim/solvers/stability.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "sim/material/material.h"

namespace palpate {
namespace {

// Springs meeting at a node of a full lattice: 6 structural, 12 face and 8 body diagonals, 6 bend.
constexpr int kMaxSpringsPerNode = 32;

ExplicitEulerCheck make_check(double k_max, double c, double rate_per_s, double dt_s) {
  ExplicitEulerCheck r;
  const double by_ratio = k_max > 0.0 ? c / k_max : INFINITY;
  const double by_rate = rate_per_s > 0.0 ? 2.0 / rate_per_s : INFINITY;
  r.max_dt_s = std::min(by_ratio, by_rate);
  if (!std::isfinite(r.max_dt_s)) r.max_dt_s = k_max > 0.0 ? 0.0 : INFINITY;  // undamped springs: never stable
  r.stable = dt_s <= r.max_dt_s;
  if (!r.stable) {
    std::ostringstream s;
    s << "explicit_euler is unstable at dt = " << dt_s << " s: its bound is dt <= ";
    if (by_ratio <= by_rate) s << "c / k_max = " << c << " / " << k_max << " = " << by_ratio << " s";
    else s << "2 / damping rate = 2 / " << rate_per_s << " = " << by_rate << " s";
    if (k_max > 0.0 && c == 0.0) s << " (no damping: never stable)";
    s << "; raise damping_Ns_per_m, lower the stiffness or choose symplectic_euler / implicit_euler";
    r.message = s.str();
  }
  return r;
}

// Largest symplectic Euler step with h^2 w2 + 2 h g <= 4 safety (infinite for no dynamics).
double symplectic_max_dt(double w2, double g, double safety) {
  const double rhs = 4.0 * safety;
  if (w2 > 0.0) return (-2.0 * g + std::sqrt(4.0 * g * g + 4.0 * w2 * rhs)) / (2.0 * w2);
  if (g > 0.0) return rhs / (2.0 * g);
  return INFINITY;
}

// "needs N substeps per frame to stay stable (step <= h s ...) but lattice.max_substeps is M", after the scheme's name
std::string substeps_message(const LatticeSpec& spec, double needed, double h_max, double w2, double g) {
  const int allowed = spec.substeps > 0 ? spec.substeps : spec.max_substeps;
  std::ostringstream s;
  s << "needs " << static_cast<long long>(std::min(needed, 1e18))
    << " substeps per frame to stay stable (step <= " << h_max << " s from h^2 w^2 + 2 h g <= 3.2, w^2 = 2 sum k / m = "
    << w2 << " s^-2, g = 2 sum c / m = " << g << " s^-1) but "
    << (spec.substeps > 0 ? "lattice.substeps is " : "lattice.max_substeps is ") << allowed;
  return s.str();
}

}  // namespace

StabilityBound stability_bound(const Lattice& lat, double safety) {
  const std::size_t n = lat.num_nodes();
  std::vector<double> ksum(n, 0.0), csum(n, 0.0);
  for (const Spring& s : lat.springs) {
    ksum[s.a] += s.k_N_per_m;
    ksum[s.b] += s.k_N_per_m;
    csum[s.a] += lat.damping_Ns_per_m;
    csum[s.b] += lat.damping_Ns_per_m;
  }
  // the cells' volume terms at rest: Gershgorin row sum 3/2 |lambda_v| l per cell over a corner (l the cell's own
  // edge), written as the spring sum that gives the same bound (a spring adds k to the diagonal and k off it); the
  // Neo-Hookean terms at rest (stiffness 2 mu I + lambda I x I) bounded the same way by 2 mu + |lambda|
  const double cell_Pa = std::abs(lat.volume_Pa) + (lat.neo_mu_Pa != 0.0 ? 2.0 * lat.neo_mu_Pa + std::abs(lat.neo_lambda_Pa) : 0.0);
  if (cell_Pa != 0.0)
    for (std::size_t k = 0; k < lat.cell_nodes.size(); ++k)
      for (int32_t node : lat.cell_nodes[k]) ksum[static_cast<std::size_t>(node)] += 0.75 * cell_Pa * lat.cell_edge_m(k);
  double w2 = 0.0, g = 0.0;
  StabilityBound b;
  for (std::size_t i = 0; i < n; ++i) {
    if (lat.fixed[i]) continue;
    if (!(lat.mass_kg[i] > 0.0)) {
      // a free node without mass: no explicit step is stable
      b.omega_max_rad_per_s = INFINITY;
      b.damping_rate_per_s = INFINITY;
      b.max_stable_dt_s = 0.0;
      return b;
    }
    w2 = std::max(w2, 2.0 * ksum[i] / lat.mass_kg[i]);
    g = std::max(g, 2.0 * csum[i] / lat.mass_kg[i]);
  }
  b.omega_max_rad_per_s = std::sqrt(w2);
  b.damping_rate_per_s = g;
  // largest h with h^2 w2 + 2 h g <= 4 s (the symplectic Euler stability region of a damped oscillator)
  b.max_stable_dt_s = symplectic_max_dt(w2, g, safety);
  return b;
}

ExplicitEulerCheck check_explicit_euler(const Lattice& lat, double dt_s) {
  double k_max = 0.0;
  for (const Spring& s : lat.springs) k_max = std::max(k_max, s.k_N_per_m);
  return make_check(k_max, lat.damping_Ns_per_m, stability_bound(lat, 1.0).damping_rate_per_s, dt_s);
}

ExplicitEulerCheck check_explicit_euler(const LatticeSpec& spec, double dt_s) {
  const double k_max = std::max({spec.structural_N_per_m, spec.shear_N_per_m, spec.bend_N_per_m});
  const double rate = 2.0 * kMaxSpringsPerNode * spec.damping_Ns_per_m / spec.node_mass_kg;
  return make_check(k_max, spec.damping_Ns_per_m, rate, dt_s);
}

std::string integrator_warning(const LatticeSpec& spec, double dt_s) {
  if (spec.material.enabled) return "";  // its lattice is not the raw keys': check_material_integrator at load
  if (spec.integrator == IntegratorKind::kExplicitEuler) {
    const double h = dt_s / std::max(1, spec.substeps);
    const ExplicitEulerCheck c = check_explicit_euler(spec, h);
    return c.stable ? "" : c.message;
  }
  if (spec.integrator != IntegratorKind::kSymplecticEuler && spec.integrator != IntegratorKind::kRk4) return "";
  // the bound of stability_bound() at an interior node of a full lattice, from the scene's parameters alone:
  // 6 structural, 20 shear and 6 bend springs meet there
  const double ksum = 6.0 * spec.structural_N_per_m + 20.0 * spec.shear_N_per_m + 6.0 * spec.bend_N_per_m;
  const int springs = (spec.structural_N_per_m > 0.0 ? 6 : 0) + (spec.shear_N_per_m > 0.0 ? 20 : 0) +
                      (spec.bend_N_per_m > 0.0 ? 6 : 0);
  const double w2 = 2.0 * ksum / spec.node_mass_kg;
  const double g = 2.0 * springs * spec.damping_Ns_per_m / spec.node_mass_kg;
  const double h_max = symplectic_max_dt(w2, g, 0.8);  // the integrator's safety factor
  if (!(h_max > 0.0) || !std::isfinite(h_max)) return "";
  const double needed = std::ceil(dt_s / h_max);
  const int allowed = spec.substeps > 0 ? spec.substeps : spec.max_substeps;
  if (needed <= allowed) return "";
  return std::string(integrator_name(spec.integrator)) + " " + substeps_message(spec, needed, h_max, w2, g) +
         ": the lattice will diverge; raise node_mass_kg, lower the stiffness or damping, or choose implicit_euler "
         "/ local_global";
}

Status check_material_integrator(const LatticeSpec& spec, double cell_m, double dt_s) {
  const IntegratorKind kind = spec.integrator;
  if (!spec.material.enabled || !(cell_m > 0.0) ||
      (kind != IntegratorKind::kExplicitEuler && kind != IntegratorKind::kSymplecticEuler && kind != IntegratorKind::kRk4))
    return Ok{};
  const MaterialSpec& m = spec.material;
  const LatticeCalibration cal = calibrate_lattice(m, cell_m);
  // a full interior node: 6 edges shared by 4 cells, 12 face diagonals by 2, 8 body diagonals; 8 cells' terms
  const double ksum = 24.0 * cal.edge_N_per_m + 32.0 * cal.diagonal_N_per_m +
                      8.0 * 0.75 * (std::abs(cal.volume_Pa) + 2.0 * cal.neo_mu_Pa + std::abs(cal.neo_lambda_Pa)) * cell_m;
  const double mass_kg = m.density_kg_per_m3 * cell_m * cell_m * cell_m;
  const double w2 = 2.0 * ksum / mass_kg;
  const double g = 2.0 * 26.0 * cal.damping_Ns_per_m / mass_kg;
  std::ostringstream what;
  what << " for material E " << m.young_modulus_Pa << " Pa, nu " << m.poisson_ratio << ", density "
       << m.density_kg_per_m3 << " kg/m^3 (material.model '" << name_of(m.model) << "') on cells of " << cell_m * 1e3
       << " mm (lattice.level " << spec.level << ")";
  const std::string remedy =
      ": the lattice would diverge; choose lattice.integrator 'implicit_euler' (any material.model), lower "
      "lattice.level or the stiffness, or ";
  if (kind == IntegratorKind::kExplicitEuler) {
    const double h = dt_s / std::max(1, spec.substeps);
    const ExplicitEulerCheck c = make_check(4.0 * cal.edge_N_per_m, cal.damping_Ns_per_m, g, h);
    if (c.stable) return Ok{};
    std::ostringstream s;
    s << "lattice.integrator 'explicit_euler' at a step of " << h << " s" << what.str() << ": its bound is dt <= "
      << c.max_dt_s << " s" << remedy << "raise lattice.substeps to at least "
      << static_cast<long long>(std::min(std::ceil(dt_s / std::max(c.max_dt_s, 1e-300)), 1e18));
    return make_error(s.str());
  }
  const double h_max = symplectic_max_dt(w2, g, 0.8);
  if (!(h_max > 0.0) || !std::isfinite(h_max)) return Ok{};
  const double needed = std::ceil(dt_s / h_max);
  if (needed <= (spec.substeps > 0 ? spec.substeps : spec.max_substeps)) return Ok{};
  return make_error("lattice.integrator '", integrator_name(kind), "' ", substeps_message(spec, needed, h_max, w2, g),
                    what.str(), remedy,
                    spec.substeps > 0 ? "raise lattice.substeps" : "raise lattice.max_substeps");
}

}  // namespace palpate
