#include "sim/reference_cases.h"

#include <cmath>
#include <string>

#include "core/mesh_io.h"
#include "sim/material.h"
#include "sim/static_solve.h"

namespace palpate {
namespace {

constexpr double kCompressionSide_m = 0.04;
constexpr double kBeamLength_m = 0.08;
constexpr int kBeamSlenderness = 8;
constexpr double kHertzBlock_m = 0.04;
constexpr double kHertzRadius_m = 0.1;
constexpr double kHertzDepth_m = 2.5e-4;

// Area share of node q of n cells along an edge of a face: 1/2 at the ends, 1 inside, over n.
double edge_share(int q, int n) { return (q == 0 || q == n ? 0.5 : 1.0) / n; }

}  // namespace

Result<Lattice> box_lattice(const MaterialSpec& material, double cube_m, int level, const std::array<int, 3>& cells) {
  const int n = 1 << (level - 1);
  for (int a = 0; a < 3; ++a)
    if (cells[a] < 1 || cells[a] > n)
      return make_error("box lattice: ", std::to_string(cells[a]), " cells along axis ", std::to_string(a),
                        " out of range [1, ", std::to_string(n), "] at level ", std::to_string(level));
  const double l = cube_m / n;
  const Vec3 size(cells[0] * l, cells[1] * l, cells[2] * l);
  // the box's faces sit a hair inside the cell planes, so no cell outside the box touches its surface
  TriMesh mesh = make_box_mesh(size * (1.0 - 1e-6), 1);
  for (Vec3& v : mesh.vertices_m) v += size / 2;
  auto grid = GridHierarchy::build(mesh, Aabb{Vec3::Zero(), Vec3::Constant(cube_m)}, level);
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
  Lattice& L = c.lattice;
  const std::size_t nodes = L.num_nodes();
  c.held_dof.assign(3 * nodes, 0);
  c.f_ext_N.assign(nodes, Vec3::Zero());
  const double side = kCompressionSide_m, d = strain * side, eps = 1e-9 * side;
  for (std::size_t i = 0; i < nodes; ++i) {
    const Vec3& r = L.rest_m[i];
    if (r.z() < eps) c.held_dof[3 * i + 2] = 1;
    if (r.z() > side - eps) {
      c.held_dof[3 * i + 2] = 1;
      L.x_m[i].z() -= d;
    }
    // rigid motion: the bottom corner at the origin holds x and y, the bottom corner at x = side holds y
    if (r.z() < eps && r.y() < eps && r.x() < eps) c.held_dof[3 * i] = c.held_dof[3 * i + 1] = 1;
    if (r.z() < eps && r.y() < eps && r.x() > side - eps) c.held_dof[3 * i + 1] = 1;
  }
  c.closed_form = material.young_modulus_Pa * side * side * d / side;
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
    if (r.x() < eps) c.held_dof[3 * i] = c.held_dof[3 * i + 1] = c.held_dof[3 * i + 2] = 1;
    if (r.x() > len - eps) {
      const int qj = static_cast<int>(std::lround(r.y() / l)), qk = static_cast<int>(std::lround(r.z() / l));
      c.f_ext_N[i].z() = -force_N * edge_share(qj, m) * edge_share(qk, m);
    }
  }
  c.closed_form = force_N * len * len * len / (3.0 * material.young_modulus_Pa * inertia_m4);
  return c;
}

Result<ReferenceCheck> check_compression(const MaterialSpec& material, int level, double strain) {
  auto c = compression_case(material, level, strain);
  if (!c) return c.error();
  ReferenceCase& rc = c.value();
  auto rep = solve_static(&rc.lattice, rc.held_dof, rc.f_ext_N);
  if (!rep) return rep.error();
  const Lattice& L = rc.lattice;
  const std::vector<Vec3> f = spring_forces_N(L, L.x_m);
  ReferenceCheck out;
  double lateral_m = 0.0;
  for (std::size_t i = 0; i < L.num_nodes(); ++i) {
    const Vec3& r = L.rest_m[i];
    // the springs push the top plate up with the compressive force
    if (r.z() > kCompressionSide_m * (1 - 1e-9)) out.model += f[i].z();
    if (r.z() < 1e-9 && r.y() < 1e-9 && r.x() > kCompressionSide_m * (1 - 1e-9)) lateral_m = L.x_m[i].x() - r.x();
  }
  out.closed_form = rc.closed_form;
  out.rel_error = (out.model - out.closed_form) / out.closed_form;
  out.poisson_effective = lateral_m / kCompressionSide_m / strain;
  out.nodes = L.num_nodes();
  out.springs = L.springs.size();
  out.newton_steps = rep.value().iterations;
  return out;
}

Result<ReferenceCheck> check_cantilever(const MaterialSpec& material, int level) {
  auto c = cantilever_case(material, level);
  if (!c) return c.error();
  ReferenceCase& rc = c.value();
  auto rep = solve_static(&rc.lattice, rc.held_dof, rc.f_ext_N);
  if (!rep) return rep.error();
  const Lattice& L = rc.lattice;
  ReferenceCheck out;
  // mean deflection of the end face, weighted by the load shares
  double load = 0.0, moment = 0.0;
  for (std::size_t i = 0; i < L.num_nodes(); ++i) {
    load += rc.f_ext_N[i].z();
    moment += rc.f_ext_N[i].z() * (L.x_m[i].z() - L.rest_m[i].z());
  }
  out.model = -moment / load;
  out.closed_form = rc.closed_form;
  out.rel_error = (out.model - out.closed_form) / out.closed_form;
  out.nodes = L.num_nodes();
  out.springs = L.springs.size();
  out.newton_steps = rep.value().iterations;
  return out;
}

Result<ReferenceCheck> check_hertz(const MaterialSpec& material, int level) {
  const int n = 1 << (level - 1);
  auto made = box_lattice(material, kHertzBlock_m, level, {n, n, n});
  if (!made) return made.error();
  Lattice lat = std::move(made).value();
  const std::size_t nodes = lat.num_nodes();
  const double side = kHertzBlock_m, eps = 1e-9 * side, d = kHertzDepth_m, radius = kHertzRadius_m;
  std::vector<uint8_t> held(3 * nodes, 0);
  std::vector<double> surface_z(nodes, 0.0);
  std::vector<uint8_t> top(nodes, 0), active(nodes, 0);
  for (std::size_t i = 0; i < nodes; ++i) {
    const Vec3& r = lat.rest_m[i];
    if (r.x() < eps) held[3 * i] = 1;
    if (r.y() < eps) held[3 * i + 1] = 1;
    if (r.z() < eps) held[3 * i + 2] = 1;
    top[i] = r.z() > side - eps;
    surface_z[i] = side - d + (r.x() * r.x() + r.y() * r.y()) / (2.0 * radius);
    active[i] = top[i] && surface_z[i] < r.z();
  }
  StaticOptions opt;
  opt.iterative = nodes > 4000;
  ReferenceCheck out;
  std::vector<Vec3> f;
  // active set: hold the nodes in contact on the sphere, release the ones it would pull, add the ones inside it
  for (int round = 0; round < 50; ++round) {
    for (std::size_t i = 0; i < nodes; ++i)
      if (top[i] && held[3 * i + 2] != active[i]) {
        held[3 * i + 2] = active[i];
        if (active[i]) lat.x_m[i].z() = surface_z[i];
      }
    auto rep = solve_static(&lat, held, {}, opt);
    if (!rep) return rep.error();
    out.newton_steps += rep.value().iterations;
    f = spring_forces_N(lat, lat.x_m);
    bool changed = false;
    for (std::size_t i = 0; i < nodes; ++i) {
      if (!top[i]) continue;
      if (active[i] && f[i].z() < 0.0) active[i] = 0, changed = true;
      else if (!active[i] && lat.x_m[i].z() > surface_z[i] + 1e-12 * side) active[i] = 1, changed = true;
    }
    if (!changed) break;
    if (round == 49) return make_error("hertz: contact set still changing after 50 rounds at level ", std::to_string(level));
  }
  for (std::size_t i = 0; i < nodes; ++i)
    if (active[i]) out.model += 4.0 * f[i].z();
  const double nu = kLatticePoissonRatio;
  const double e_star = material.young_modulus_Pa / (1.0 - nu * nu);
  out.closed_form = 4.0 / 3.0 * e_star * std::sqrt(radius) * std::pow(d, 1.5);
  out.rel_error = (out.model - out.closed_form) / out.closed_form;
  out.nodes = nodes;
  out.springs = lat.springs.size();
  return out;
}

}  // namespace palpate
