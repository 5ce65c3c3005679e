#include "sim/solvers/rest.h"

#include <algorithm>

#include "sim/lattice/forces.h"
#include "sim/lattice/hanging.h"

namespace palpate {

double max_force_N(const std::vector<Vec3>& f_N) {
  double m = 0.0;
  for (const Vec3& f : f_N) m = std::max(m, f.norm());
  return m;
}

bool lattice_at_rest(const Lattice& lat, const std::vector<Vec3>& f_ext_N, double kinetic_J, double force_N,
                     std::vector<Vec3>* scratch) {
  if (!(kinetic_energy_J(lat) < kinetic_J)) return false;
  compute_forces(lat, lat.x_m, lat.v_m_per_s, f_ext_N, scratch);
  // a refined lattice rests when its free coordinates do: hanging nodes' forces belong to their masters
  if (!lat.hanging.empty()) {
    fold_hanging(lat, scratch);
    for (std::size_t i = 0; i < lat.num_nodes(); ++i)
      if (lat.fixed[i]) (*scratch)[i].setZero();
  }
  return max_force_N(*scratch) < force_N;
}

}  // namespace palpate
