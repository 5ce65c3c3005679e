#include "sim/solvers/strain_limit.h"

#include <cmath>

namespace palpate {

int limit_strain(Lattice* lat, double limit, int iterations) {
  int corrections = 0;
  for (int it = 0; it < iterations; ++it) {
    int this_sweep = 0;
    for (const Spring& s : lat->springs) {
      const double wa = lat->fixed[s.a] ? 0.0 : 1.0 / lat->mass_kg[s.a];
      const double wb = lat->fixed[s.b] ? 0.0 : 1.0 / lat->mass_kg[s.b];
      if (wa + wb == 0.0 || s.rest_m <= 0.0) continue;
      Vec3 d = lat->x_m[s.b] - lat->x_m[s.a];
      double len = d.norm();
      const double lo = (1.0 - limit) * s.rest_m, hi = (1.0 + limit) * s.rest_m;
      if (len >= lo && len <= hi) continue;
      // a collapsed spring has no direction of its own: push it apart along its rest direction
      const Vec3 u = len > 1e-12 * s.rest_m ? Vec3(d / len) : Vec3((lat->rest_m[s.b] - lat->rest_m[s.a]) / s.rest_m);
      if (!(len > 1e-12 * s.rest_m)) len = 0.0;
      const double err = len > hi ? len - hi : len - lo;  // > 0 too long, < 0 too short
      lat->x_m[s.a] += (wa / (wa + wb)) * err * u;
      lat->x_m[s.b] -= (wb / (wa + wb)) * err * u;
      // remove the relative normal velocity that would strain it further
      const double vn = (lat->v_m_per_s[s.b] - lat->v_m_per_s[s.a]).dot(u);
      if ((err > 0.0 && vn > 0.0) || (err < 0.0 && vn < 0.0)) {
        lat->v_m_per_s[s.a] += (wa / (wa + wb)) * vn * u;
        lat->v_m_per_s[s.b] -= (wb / (wa + wb)) * vn * u;
      }
      ++this_sweep;
    }
    corrections += this_sweep;
    if (this_sweep == 0) break;
  }
  return corrections;
}

}  // namespace palpate
