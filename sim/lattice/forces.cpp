#include "sim/lattice/forces.h"

#include <algorithm>
#include <cmath>

#include "sim/material/neo_hookean_term.h"
#include "sim/material/volume_term.h"

namespace palpate {
namespace {

// Lengths below this fraction of the rest length count as zero (direction undefined).
constexpr double kDegenerateLength = 1e-12;

bool degenerate(const Spring& s, double len) { return !(len > kDegenerateLength * s.rest_m + 1e-300); }

}  // namespace

Vec3 spring_force_on_a(const Spring& s, const Vec3& d) {
  const double len = d.norm();
  if (degenerate(s, len)) return Vec3::Zero();
  return s.k_N_per_m * (len - s.rest_m) / len * d;
}

Mat3 spring_stiffness_block(const Spring& s, const Vec3& d, bool clamp_compression) {
  const double len = d.norm();
  if (degenerate(s, len)) return s.k_N_per_m * Mat3::Identity();
  const Vec3 u = d / len;
  const Mat3 uu = u * u.transpose();
  double transverse = 1.0 - s.rest_m / len;
  if (clamp_compression) transverse = std::max(0.0, transverse);
  return s.k_N_per_m * (uu + transverse * (Mat3::Identity() - uu));
}

void compute_forces(const Lattice& lat, const std::vector<Vec3>& x_m, const std::vector<Vec3>& v_m_per_s,
                    const std::vector<Vec3>& f_ext_N, std::vector<Vec3>* f_N) {
  const std::size_t n = lat.num_nodes();
  f_N->resize(n);
  // gravity and external forces
  if (lat.gravity_m_per_s2.isZero()) {
    if (f_ext_N.empty()) std::fill(f_N->begin(), f_N->end(), Vec3::Zero());
    else std::copy(f_ext_N.begin(), f_ext_N.begin() + static_cast<std::ptrdiff_t>(n), f_N->begin());
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      (*f_N)[i] = lat.mass_kg[i] * lat.gravity_m_per_s2;
      if (!f_ext_N.empty()) (*f_N)[i] += f_ext_N[i];
    }
  }
  const double c = lat.damping_Ns_per_m;
  for (const Spring& s : lat.springs) {
    Vec3 f = spring_force_on_a(s, x_m[s.b] - x_m[s.a]);                 // eq. (2)
    if (c != 0.0) f += c * (v_m_per_s[s.b] - v_m_per_s[s.a]);           // eq. (4) on node a
    (*f_N)[s.a] += f;
    (*f_N)[s.b] -= f;
  }
  add_volume_forces(lat, x_m, f_N);
  add_neo_hookean_forces(lat, x_m, f_N);
  for (std::size_t i = 0; i < n; ++i)
    if (lat.fixed[i]) (*f_N)[i].setZero();
  for (std::size_t d = 0; d < lat.held_dof.size(); ++d)
    if (lat.held_dof[d]) (*f_N)[d / 3][static_cast<int>(d % 3)] = 0.0;
}

double elastic_energy_J(const Lattice& lat, const std::vector<Vec3>& x_m) {
  double e = 0.0;
  for (const Spring& s : lat.springs) {
    const double stretch = (x_m[s.b] - x_m[s.a]).norm() - s.rest_m;
    e += 0.5 * s.k_N_per_m * stretch * stretch;
  }
  return e + volume_energy_J(lat, x_m) + neo_hookean_energy_J(lat, x_m);
}

double lattice_energy_J(const Lattice& lat) {
  double e = elastic_energy_J(lat, lat.x_m);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    e += 0.5 * lat.mass_kg[i] * lat.v_m_per_s[i].squaredNorm();
    e -= lat.mass_kg[i] * lat.gravity_m_per_s2.dot(lat.x_m[i] - lat.rest_m[i]);
  }
  return e;
}

double kinetic_energy_J(const Lattice& lat) {
  double e = 0.0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (!lat.fixed[i]) e += 0.5 * lat.mass_kg[i] * lat.v_m_per_s[i].squaredNorm();
  return e;
}

double max_strain(const Lattice& lat) {
  // the extreme squared length ratios (l / l0)^2, found without a square root or a division per spring (this runs
  // after every step); non-finite lengths fail both tests and are skipped, as std::max skipped them
  double hi = 1.0, lo = 1.0;
  for (const Spring& s : lat.springs) {
    if (s.rest_m <= 0.0) continue;
    const double l2 = (lat.x_m[s.b] - lat.x_m[s.a]).squaredNorm(), l02 = s.rest_m * s.rest_m;
    if (l2 > hi * l02) hi = l2 / l02;
    else if (l2 < lo * l02) lo = l2 / l02;
  }
  return std::max(std::sqrt(hi) - 1.0, 1.0 - std::sqrt(lo));
}

}  // namespace palpate
