#include "sim/reference/reference_cases.h"

#include <cmath>
#include <string>

#include "core/mesh_io.h"
#include "sim/material/material.h"
#include "sim/solvers/static_solve.h"

namespace palpate {
namespace {

constexpr double kCompressionSide_m = 0.04;
constexpr double kBeamLength_m = 0.08;
constexpr int kBeamSlenderness = 8;

// Area share of node q of n cells along an edge of a face: 1/2 at the ends, 1 inside, over n.
double edge_share(int q, int n) { return (q == 0 || q == n ? 0.5 : 1.0) / n; }

}  // namespace

Result<GridHierarchy> box_grid(const Vec3& size_m, double cube_m, int levels) {
  // the box's faces sit a hair inside the cell planes, so no cell outside the box touches its surface
  TriMesh mesh = make_box_mesh(size_m * (1.0 - 1e-6), 1);
  for (Vec3& v : mesh.vertices_m) v += size_m / 2;
  return GridHierarchy::build(mesh, Aabb{Vec3::Zero(), Vec3::Constant(cube_m)}, levels);
}

Result<Lattice> box_lattice(const MaterialSpec& material, double cube_m, int level, const std::array<int, 3>& cells) {
  const int n = 1 << (level - 1);
  for (int a = 0; a < 3; ++a)
    if (cells[a] < 1 || cells[a] > n)
      return make_error("box lattice: ", std::to_string(cells[a]), " cells along axis ", std::to_string(a),
                        " out of range [1, ", std::to_string(n), "] at level ", std::to_string(level));
  const double l = cube_m / n;
  auto grid = box_grid(Vec3(cells[0] * l, cells[1] * l, cells[2] * l), cube_m, level);
  if (!grid) return grid.error();
  LatticeSpec spec;
  spec.level = level;
  spec.material = material;
  spec.material.enabled = true;
  spec.gravity_m_per_s2 = Vec3::Zero();
  auto lat = build_lattice(grid.value(), spec, region_cells(grid.value(), level, {0, 0, 0}, n));
  if (!lat) return lat.error();
  std::fill(lat.value().fixed.begin(), lat.value().fixed.end(), 0);
  return lat;
}

Result<ReferenceCase> compression_case(const MaterialSpec& material, int level, double strain) {
  const int n = 1 << (level - 1);
  auto lat = box_lattice(material, kCompressionSide_m, level, {n, n, n});
  if (!lat) return lat.error();
  ReferenceCase c;
  c.lattice = std::move(lat).value();
  const Lattice& L = c.lattice;
  const std::size_t nodes = L.num_nodes();
  c.f_ext_N.assign(nodes, Vec3::Zero());
  const double side = kCompressionSide_m, eps = 1e-9 * side;
  const double force_N = material.young_modulus_Pa * strain * side * side;
  for (std::size_t i = 0; i < nodes; ++i) {
    const Vec3& r = L.rest_m[i];
    const int qi = static_cast<int>(std::lround(r.x() / L.cell_m)), qj = static_cast<int>(std::lround(r.y() / L.cell_m));
    const double share = force_N * edge_share(qi, n) * edge_share(qj, n);
    if (r.z() < eps) c.f_ext_N[i].z() = share;
    if (r.z() > side - eps) c.f_ext_N[i].z() = -share;
  }
  c.closed_form = strain * side;
  return c;
}

Result<ReferenceCase> cantilever_case(const MaterialSpec& material, int level) {
  const int n = 1 << (level - 1);
  if (n < kBeamSlenderness)
    return make_error("cantilever: level ", std::to_string(level), " has ", std::to_string(n),
                      " cells along the beam; needs at least ", std::to_string(kBeamSlenderness), " (level >= 4)");
  const int m = n / kBeamSlenderness;  // cells across the section
  auto lat = box_lattice(material, kBeamLength_m, level, {n, m, m});
  if (!lat) return lat.error();
  ReferenceCase c;
  c.lattice = std::move(lat).value();
  const Lattice& L = c.lattice;
  const std::size_t nodes = L.num_nodes();
  const double len = kBeamLength_m, h = len / kBeamSlenderness, l = L.cell_m, eps = 1e-9 * len;
  const double inertia_m4 = h * h * h * h / 12.0;
  const double force_N = 3.0 * material.young_modulus_Pa * inertia_m4 * (1e-4 * len) / (len * len * len);
  c.held_dof.assign(3 * nodes, 0);
  c.f_ext_N.assign(nodes, Vec3::Zero());
  for (std::size_t i = 0; i < nodes; ++i) {
    const Vec3& r = L.rest_m[i];
    if (r.x() < eps) {
      c.held_dof[3 * i] = c.held_dof[3 * i + 1] = c.held_dof[3 * i + 2] = 1;
      c.lattice.fixed[i] = 1;
    }
    if (r.x() > len - eps) {
      const int qj = static_cast<int>(std::lround(r.y() / l)), qk = static_cast<int>(std::lround(r.z() / l));
      c.f_ext_N[i].z() = -force_N * edge_share(qj, m) * edge_share(qk, m);
    }
  }
  c.closed_form = force_N * len * len * len / (3.0 * material.young_modulus_Pa * inertia_m4);
  c.lattice.touch();
  return c;
}

Result<ReferenceCheck> check_compression(const MaterialSpec& material, int level, double strain,
                                         const SettleOptions& settle_options) {
  auto c = compression_case(material, level, strain);
  if (!c) return c.error();
  ReferenceCase& rc = c.value();
  Lattice& L = rc.lattice;
  ReferenceCheck out;
  auto rep = settle(&L, rc.f_ext_N, settle_options);
  if (!rep) return rep.error();
  out.settle = rep.value();
  // shortening: mean top face height change minus the bottom's; lateral: mean x of the x = side face minus x = 0
  const double side = kCompressionSide_m, eps = 1e-9 * side;
  double top = 0.0, bottom = 0.0, right = 0.0, left = 0.0;
  int n_top = 0, n_bottom = 0, n_right = 0, n_left = 0;
  for (std::size_t i = 0; i < L.num_nodes(); ++i) {
    const Vec3& r = L.rest_m[i];
    const Vec3 u = L.x_m[i] - r;
    if (r.z() > side - eps) top += u.z(), ++n_top;
    if (r.z() < eps) bottom += u.z(), ++n_bottom;
    if (r.x() > side - eps) right += u.x(), ++n_right;
    if (r.x() < eps) left += u.x(), ++n_left;
  }
  out.model = bottom / n_bottom - top / n_top;
  out.closed_form = rc.closed_form;
  out.rel_error = out.closed_form / out.model - 1.0;
  out.poisson_effective = (right / n_right - left / n_left) / side / strain;
  out.nodes = L.num_nodes();
  out.springs = L.springs.size();
  return out;
}

double cantilever_deflection_m(const ReferenceCase& c, const Lattice& lat) {
  double load = 0.0, moment = 0.0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    load += c.f_ext_N[i].z();
    moment += c.f_ext_N[i].z() * (lat.x_m[i].z() - lat.rest_m[i].z());
  }
  return -moment / load;
}

Result<ReferenceCheck> check_cantilever(const MaterialSpec& material, int level, const SettleOptions& settle_options) {
  auto c = cantilever_case(material, level);
  if (!c) return c.error();
  ReferenceCase& rc = c.value();
  Lattice& L = rc.lattice;
  ReferenceCheck out;
  auto rep = settle(&L, rc.f_ext_N, settle_options);
  if (!rep) return rep.error();
  out.settle = rep.value();
  out.model = cantilever_deflection_m(rc, L);
  out.closed_form = rc.closed_form;
  out.rel_error = out.closed_form / out.model - 1.0;
  out.nodes = L.num_nodes();
  out.springs = L.springs.size();
  return out;
}

double neo_hookean_uniaxial_Pa(double mu_Pa, double lambda_Pa, double a, double* lateral) {
  // lateral stretch: mu (b^2 - 1) + lambda ln(a b^2) rises with b; bisection between 1e-3 and 1e3
  double lo = 1e-3, hi = 1e3;
  for (int it = 0; it < 200; ++it) {
    const double b = std::sqrt(lo * hi);
    (mu_Pa * (b * b - 1.0) + lambda_Pa * std::log(a * b * b) > 0.0 ? hi : lo) = b;
  }
  const double b = std::sqrt(lo * hi);
  if (lateral != nullptr) *lateral = b;
  return mu_Pa * (a - 1.0 / a) + lambda_Pa * std::log(a * b * b) / a;
}

Result<ReferenceCheck> check_large_compression(const MaterialSpec& material, int level, double strain,
                                               const SettleOptions& settle_options) {
  if (level < 2) return make_error("large compression: level ", std::to_string(level), " has no centre node (needs >= 2)");
  const double nu = material.poisson_ratio, e = material.young_modulus_Pa;
  const double mu = e / (2.0 * (1.0 + nu)), lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  auto c = compression_case(material, level, strain);
  if (!c) return c.error();
  Lattice& L = c.value().lattice;
  const std::size_t nodes = L.num_nodes();
  const double side = kCompressionSide_m, half = 0.5 * side, eps = 1e-9 * side;
  // frictionless plates: the top and bottom faces held in z, free to spread; the bottom face's centre held in x and
  // y and its node on the x = side edge's middle in y (no rigid motion; by symmetry neither moves sideways)
  L.held_dof.assign(3 * nodes, 0);
  std::vector<std::size_t> top;
  for (std::size_t i = 0; i < nodes; ++i) {
    const Vec3& r = L.rest_m[i];
    const bool bottom = r.z() < eps;
    if (bottom || r.z() > side - eps) L.held_dof[3 * i + 2] = 1;
    if (!bottom) {
      if (r.z() > side - eps) top.push_back(i);
      continue;
    }
    const bool mid_y = std::abs(r.y() - half) < eps;
    if (mid_y && std::abs(r.x() - half) < eps) L.held_dof[3 * i] = L.held_dof[3 * i + 1] = 1;
    if (mid_y && r.x() > side - eps) L.held_dof[3 * i + 1] = 1;
  }
  // the plates moved together in increments, each run to rest from the last one squashed uniformly (the closed
  // form's lateral stretch as the first guess: a nearly incompressible cell squashed in z only would burst)
  constexpr int kIncrements = 3;
  ReferenceCheck out;
  double previous = 1.0, previous_lateral = 1.0;
  for (int step = 1; step <= kIncrements; ++step) {
    const double stretch = 1.0 - strain * step / kIncrements;
    double guess_lateral = 1.0;
    neo_hookean_uniaxial_Pa(mu, lambda, stretch, &guess_lateral);
    const double spread = guess_lateral / previous_lateral;
    for (Vec3& x : L.x_m) {
      x.z() *= stretch / previous;
      x.x() = half + (x.x() - half) * spread;
      x.y() = half + (x.y() - half) * spread;
    }
    previous = stretch;
    previous_lateral = guess_lateral;
    auto rep = settle(&L, {}, settle_options);
    if (!rep)
      return make_error("large compression, step ", std::to_string(step), " of ", std::to_string(kIncrements), ": ",
                        rep.error().message);
    out.settle.frames += rep.value().frames;
    out.settle.substeps += rep.value().substeps;
    out.settle.ms_per_frame_p50 = std::max(out.settle.ms_per_frame_p50, rep.value().ms_per_frame_p50);
    out.settle.residual_rel = rep.value().residual_rel;
  }
  // the plates' force: the lattice's push on the top face's nodes
  const std::vector<Vec3> f = spring_forces_N(L, L.x_m);
  double push_N = 0.0;
  for (std::size_t i : top) push_N += f[i].z();
  double right = 0.0, left = 0.0;
  int n_right = 0, n_left = 0;
  for (std::size_t i = 0; i < nodes; ++i) {
    const Vec3& r = L.rest_m[i];
    if (r.x() > side - eps) right += L.x_m[i].x(), ++n_right;
    if (r.x() < eps) left += L.x_m[i].x(), ++n_left;
  }
  double lateral = 1.0;
  out.model = push_N;
  out.closed_form = -neo_hookean_uniaxial_Pa(mu, lambda, 1.0 - strain, &lateral) * side * side;
  out.rel_error = out.model / out.closed_form - 1.0;
  out.poisson_effective = (right / n_right - left / n_left) / side / lateral - 1.0;
  out.nodes = nodes;
  out.springs = L.springs.size();
  return out;
}

}  // namespace palpate
