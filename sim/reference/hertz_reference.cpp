#include "sim/reference/hertz_reference.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/grid_hierarchy.h"
#include "sim/lattice/graded_zone.h"
#include "sim/material/material.h"
#include "sim/reference/reference_cases.h"
#include "sim/lattice/refined_lattice.h"
#include "sim/contact/sphere_contact.h"

namespace palpate {
namespace {

// The quarter x, y, z in [0, q] (q half the block's scaled side; its depth is that too) as a cube grid of cells
// side / 2^(level-1): uniform at `level`, or graded from coarse_level to it around the sphere's axis.
Result<Lattice> hertz_quarter(const MaterialSpec& material, int level, double zone_radius_m, const HertzSolvedOptions& o) {
  const double q = 0.5 * o.block_scale * o.block_side_m;
  const int shift = o.block_scale == 4 ? 2 : o.block_scale == 2 ? 1 : 0;
  const int fine = level - 1 + shift, coarse = (o.coarse_level > 0 ? o.coarse_level : level) - 1 + shift;
  if (fine > GridHierarchy::kMaxLevels)
    return make_error("level ", std::to_string(level), " at block scale ", std::to_string(o.block_scale),
                      " needs a grid of ", std::to_string(fine), " levels over the quarter (at most ",
                      std::to_string(GridHierarchy::kMaxLevels), ")");
  if (coarse < 1 || coarse > fine)
    return make_error("coarse level ", std::to_string(o.coarse_level), " is not in [", std::to_string(2 - shift), ", ",
                      std::to_string(level), "]");
  auto grid = box_grid(Vec3::Constant(q), q, fine);
  if (!grid) return grid.error();
  LatticeSpec spec;
  spec.level = coarse;
  spec.material = material;
  spec.material.enabled = true;
  const auto cells = region_cells(grid.value(), coarse, {0, 0, 0}, grid.value().cells_per_axis(coarse));
  // the zone centred half a fine cell in from the symmetry planes, where the cells on both sides of x = 0 and y = 0
  // are the block's: the zone reaches straight down
  const double half = 0.5 * grid.value().cell_size_m(fine);
  auto lat = coarse == fine ? build_lattice(grid.value(), spec, cells)
                            : build_refined_lattice(grid.value(), spec, cells, fine,
                                                    graded_leaves(grid.value(), coarse, cells, fine, Vec3(half, half, q),
                                                                  zone_radius_m));
  if (!lat) return lat.error();
  std::fill(lat.value().fixed.begin(), lat.value().fixed.end(), 0);
  return lat;
}

}  // namespace

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
  if (options.block_scale != 1 && options.block_scale != 2 && options.block_scale != 4)
    return make_error("hertz block: block scale ", std::to_string(options.block_scale), " is not 1, 2 or 4");
  const int n = 1 << (level - 1);
  // the quarter x, y in [0, 4 cm], z in [0, 4 cm]: n/2 x n/2 x n/2 cells of 8 cm / n (scaled: as many more cells)
  const double zone_radius_m = options.zone_over_contact * std::sqrt(radius_m * depth_m);
  const bool uniform = options.coarse_level == 0 && options.block_scale == 1;
  auto built = uniform ? box_lattice(material, options.block_side_m, level, {n / 2, n / 2, n / 2})
                       : hertz_quarter(material, level, zone_radius_m, options);
  if (!built) return make_error("hertz block level ", std::to_string(level), ": ", built.error().message);
  Lattice lat = std::move(built).value();
  lat.gravity_m_per_s2 = Vec3::Zero();
  const double l = lat.cell_m, eps = 1e-6 * l, top = uniform ? (n / 2) * l : 0.5 * options.block_scale * options.block_side_m;
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
  h.hanging = lat.hanging.size();
  for (const SurfaceSample& smp : samples) {
    const Vec3 p = sample_position(smp, lat.x_m);
    if ((p - centre).norm() < radius_m) h.contact_radius_m = std::max(h.contact_radius_m, std::hypot(p.x(), p.y()));
  }
  return h;
}

}  // namespace palpate
