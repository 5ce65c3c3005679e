#include "sim/hertz_reference.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "sim/material.h"
#include "sim/reference_cases.h"
#include "sim/sphere_contact.h"

namespace palpate {

double hertz_force_N(double young_modulus_Pa, double poisson_ratio, double radius_m, double depth_m) {
  const double e_star = young_modulus_Pa / (1.0 - poisson_ratio * poisson_ratio);
  return 4.0 / 3.0 * e_star * std::sqrt(radius_m) * std::pow(std::max(depth_m, 0.0), 1.5);
}

double represented_poisson(const MaterialSpec& material) {
  return material.model == MaterialModel::kSprings ? kLatticePoissonRatio : material.poisson_ratio;
}

Result<HertzSolved> solve_hertz_block(const MaterialSpec& material, int level, double radius_m, double depth_m,
                                      const HertzSolvedOptions& options) {
  if (level < 3)
    return make_error("hertz block: level ", std::to_string(level), " has fewer than 2 cells across its quarter (needs >= 3)");
  const int n = 1 << (level - 1);
  // the quarter x, y in [0, 4 cm], z in [0, 4 cm]: n/2 x n/2 x n/2 cells of 8 cm / n
  auto built = box_lattice(material, options.block_side_m, level, {n / 2, n / 2, n / 2});
  if (!built) return make_error("hertz block level ", std::to_string(level), ": ", built.error().message);
  Lattice lat = std::move(built).value();
  lat.gravity_m_per_s2 = Vec3::Zero();
  const double l = lat.cell_m, eps = 1e-6 * l, top = (n / 2) * l;
  // floor fixed (or sliding); the symmetry planes x = 0 and y = 0 slide (their normal DOF held)
  std::vector<uint8_t> held(3 * lat.num_nodes(), 0);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    const Vec3& p = lat.rest_m[i];
    if (p.z() < eps) held[3 * i + 2] = 1;
    if (p.z() < eps && !options.sliding_floor) held[3 * i] = held[3 * i + 1] = 1;
    if (p.x() < eps) held[3 * i] = 1;
    if (p.y() < eps) held[3 * i + 1] = 1;
  }
  const std::vector<SurfaceSample> samples = lattice_surface_samples(lat, options.samples_per_edge, Vec3::UnitZ());
  SphereContactOptions so;
  so.penalty_Pa_per_m = contact_penalty_Pa_per_m(material.young_modulus_Pa, l);
  so.iterative = options.iterative;
  const Vec3 centre(0.0, 0.0, top + radius_m - depth_m);
  auto solved = solve_sphere_contact(&lat, held, samples, centre, radius_m, so);
  if (!solved)
    return make_error("hertz block level ", std::to_string(level), ", depth ", std::to_string(depth_m), " m: ",
                      solved.error().message);
  const SphereContactResult& s = solved.value();
  HertzSolved h;
  h.force_N = 4.0 * s.force_N.z();
  h.closed_form_N = hertz_force_N(material.young_modulus_Pa, represented_poisson(material), radius_m, depth_m);
  h.rel_error = h.force_N / h.closed_form_N - 1.0;
  h.max_penetration_m = s.max_penetration_m;
  h.active = s.active;
  h.iterations = s.iterations;
  h.nodes = lat.num_nodes();
  h.springs = lat.springs.size();
  for (const SurfaceSample& smp : samples) {
    const Vec3 p = sample_position(smp, lat.x_m);
    if ((p - centre).norm() < radius_m) h.contact_radius_m = std::max(h.contact_radius_m, std::hypot(p.x(), p.y()));
  }
  return h;
}

}  // namespace palpate
