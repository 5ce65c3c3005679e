#include "sim/forces.h"

namespace palpate {

void compute_forces(const Lattice& lat, const std::vector<Vec3>& x_m, const std::vector<Vec3>& v_m_per_s,
                    const std::vector<Vec3>& f_ext_N, std::vector<Vec3>* f_N) {
  const std::size_t n = lat.num_nodes();
  f_N->resize(n);
  // gravity and external forces
  for (std::size_t i = 0; i < n; ++i) {
    (*f_N)[i] = lat.mass_kg[i] * lat.gravity_m_per_s2;
    if (!f_ext_N.empty()) (*f_N)[i] += f_ext_N[i];
  }
  const double c = lat.damping_Ns_per_m;
  for (const Spring& s : lat.springs) {
    const Vec3 d = x_m[s.b] - x_m[s.a];
    const double len = d.norm();
    Vec3 f = c * (v_m_per_s[s.b] - v_m_per_s[s.a]);  // eq. (4) on node a
    if (len > 1e-12 * s.rest_m + 1e-300) f += s.k_N_per_m * (len - s.rest_m) / len * d;  // eq. (2)
    (*f_N)[s.a] += f;
    (*f_N)[s.b] -= f;
  }
  for (std::size_t i = 0; i < n; ++i)
    if (lat.fixed[i]) (*f_N)[i].setZero();
}

double lattice_energy_J(const Lattice& lat) {
  double e = 0.0;
  for (const Spring& s : lat.springs) {
    const double stretch = (lat.x_m[s.b] - lat.x_m[s.a]).norm() - s.rest_m;
    e += 0.5 * s.k_N_per_m * stretch * stretch;
  }
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    e += 0.5 * lat.mass_kg[i] * lat.v_m_per_s[i].squaredNorm();
    e -= lat.mass_kg[i] * lat.gravity_m_per_s2.dot(lat.x_m[i] - lat.rest_m[i]);
  }
  return e;
}

}  // namespace palpate
