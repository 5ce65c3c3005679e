#pragma once
// Small lattices built by hand (chains, oscillators) and helpers shared by the stability tests.

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "sim/lattice/forces.h"
#include "sim/solvers/integrator.h"
#include "sim/lattice/lattice.h"
#include "support/fixtures.h"

namespace palpate::test {

/// Forces against the energy they come from, by two-sided differences of step step_cells * cell over every node's
/// coordinates: the largest |f + dE/dx| over the largest |f| (mismatch), and that largest |f|.
struct GradientCheck {
  double mismatch = 0.0;
  double largest_force_N = 0.0;
};
template <class Energy>
GradientCheck gradient_check(const Lattice& lat, const std::vector<Vec3>& f, Energy energy_J, double step_cells) {
  const double h = step_cells * lat.cell_m;
  double worst = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    for (int a = 0; a < 3; ++a) {
      std::vector<Vec3> xp = lat.x_m, xm = lat.x_m;
      xp[i][a] += h;
      xm[i][a] -= h;
      worst = std::max(worst, std::abs(f[i][a] + (energy_J(xp) - energy_J(xm)) / (2 * h)));
      scale = std::max(scale, std::abs(f[i][a]));
    }
  return {worst / scale, scale};
}

/// Every integrator, in a fixed order.
inline const std::vector<IntegratorKind>& all_integrators() {
  static const std::vector<IntegratorKind> k{IntegratorKind::kExplicitEuler, IntegratorKind::kSymplecticEuler,
                                             IntegratorKind::kImplicitEuler, IntegratorKind::kLocalGlobal,
                                             IntegratorKind::kRk4};
  return k;
}

/// The integrators that must survive frame-size steps.
inline const std::vector<IntegratorKind>& robust_integrators() {
  static const std::vector<IntegratorKind> k{IntegratorKind::kSymplecticEuler, IntegratorKind::kImplicitEuler,
                                             IntegratorKind::kLocalGlobal, IntegratorKind::kRk4};
  return k;
}

/// A chain of n_springs springs along `axis` (unit vector), spacing a_m; node 0 fixed, optionally the last too.
inline Lattice make_chain(int n_springs, double a_m, double k_N_per_m, double mass_kg, double c_Ns_per_m,
                          const Vec3& axis = Vec3::UnitX(), bool fix_last = false) {
  Lattice lat;
  lat.cell_m = a_m;
  lat.damping_Ns_per_m = c_Ns_per_m;
  for (int i = 0; i <= n_springs; ++i) {
    lat.rest_m.push_back(i * a_m * axis);
    lat.grid_node.push_back(i);
  }
  const std::size_t n = lat.rest_m.size();
  lat.x_m = lat.rest_m;
  lat.v_m_per_s.assign(n, Vec3::Zero());
  lat.mass_kg.assign(n, mass_kg);
  lat.fixed.assign(n, 0);
  lat.fixed[0] = 1;
  if (fix_last) lat.fixed[n - 1] = 1;
  for (int i = 0; i < n_springs; ++i) {
    Spring s;
    s.a = i;
    s.b = i + 1;
    s.rest_m = a_m;
    s.k_N_per_m = k_N_per_m;
    lat.springs.push_back(s);
  }
  lat.springs_per_family[0] = n_springs;
  lat.touch();
  return lat;
}

/// A block of n^3 cells of side 1 cm in the corner of a level-`level` grid filled with solid cells; with
/// n < 2^(level-1) the nodes touching the rest of the grid are fixed (region border), else none unless fix_floor.
inline Lattice make_block(int level, int n, const LatticeSpec& spec_in) {
  LatticeSpec spec = spec_in;
  spec.level = level;
  const auto box = make_box_model(0.01 * (1 << (level - 1)), level);
  std::vector<int32_t> cells;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) cells.push_back(box.grid.linear_index({i, j, k}, level));
  return build_lattice(box.grid, spec, cells).value();
}

/// Step options for a scheme with the given fixed substeps (0 = automatic) and a generous cap.
inline StepOptions opts(IntegratorKind kind, int substeps = 0, int iterations = 0) {
  StepOptions o;
  o.kind = kind;
  o.substeps = substeps;
  o.iterations = iterations;
  o.max_substeps = 100000;
  return o;
}

/// Spring potential plus kinetic energy (no gravity), J.
inline double energy_J(const Lattice& lat) { return lattice_energy_J(lat); }

/// Deterministic random velocities on free nodes, scaled to kinetic energy e_J.
inline void kick(Lattice* lat, double e_J, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t i = 0; i < lat->num_nodes(); ++i)
    if (!lat->fixed[i]) lat->v_m_per_s[i] = Vec3(u(rng), u(rng), u(rng));
  const double ke = kinetic_energy_J(*lat);
  for (auto& v : lat->v_m_per_s) v *= std::sqrt(e_J / ke);
}

/// True when every position and velocity is finite.
inline bool all_finite(const Lattice& lat) {
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (!lat.x_m[i].allFinite() || !lat.v_m_per_s[i].allFinite()) return false;
  return true;
}

}  // namespace palpate::test
