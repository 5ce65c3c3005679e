// The cells' volume and Neo-Hookean terms on a refined lattice: each cell's term at its own edge, so a graded
// lattice of material.model volumetric or neo_hookean is the same solid as a uniform one.
#include <gtest/gtest.h>

#include "sim/pressed_rest.h"
#include "sim/sim_test_util.h"

#include <cmath>
#include <random>

#include "sim/lattice/lattice.h"
#include "sim/material/neo_hookean_term.h"
#include "sim/lattice/refined_lattice.h"
#include "sim/lattice/region.h"
#include "sim/material/volume_term.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

using test::make_box_model;

constexpr double kE_Pa = 1e5, kSide_m = 0.04;

LatticeSpec cell_term_spec(MaterialModel model, double nu, int level) {
  LatticeSpec s;
  s.level = level;
  s.radius_cells = 64;
  s.integrator = IntegratorKind::kImplicitEuler;
  s.material = test::soft_material(nu, model);
  s.material.young_modulus_Pa = kE_Pa;
  s.material.density_kg_per_m3 = 1000.0;
  s.material.stiffness_damping_s = 0.02;
  return s;
}

// The 4 cm box at level 2 (2 cm cells) graded to level 4 (5 mm) around a point on its top face: cells of three sizes.
Lattice graded_box(const test::BoxModel& box, const LatticeSpec& spec) {
  const auto cells = region_cells(box.grid, 2, {0, 0, 0}, 64);
  return build_refined_lattice(box.grid, spec, cells, 4, graded_leaves(box.grid, 2, cells, 4, Vec3(0.0049, 0.0, 0.02), 2e-3))
      .value();
}

// Uniaxial compression by a pressure on the top face, on sliding supports (the floor held in z, the planes x = 0 and
// y = 0 in x and y): the solid's answer is affine, top face down p h / E, sides out nu p / E. Returns the top nodes'
// mean drop over p h / E and the top corner's lateral strain over p / E (closed form: 1 and nu), after the
// lattice came to rest with its hanging nodes on their faces.
std::pair<double, double> compressed(Lattice& lat) {
  const double p_Pa = 100.0, top = 0.5 * kSide_m, eps = 1e-9;
  const std::size_t n = lat.num_nodes();
  std::vector<uint8_t> hangs(n, 0);
  mark_hanging(lat, &hangs);
  lat.held_dof.assign(3 * n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (hangs[i]) continue;  // they follow their masters, which lie in the same plane
    const Vec3& r = lat.rest_m[i];
    lat.held_dof[3 * i + 0] = std::abs(r.x()) < eps;
    lat.held_dof[3 * i + 1] = std::abs(r.y()) < eps;
    lat.held_dof[3 * i + 2] = std::abs(r.z() + top) < eps;
  }
  // the pressure as the nodal loads of each top face (a quarter of its area to each corner; a hanging corner's share
  // is folded onto its masters by the solver)
  std::vector<Vec3> f_ext(n, Vec3::Zero());
  for (std::size_t k = 0; k < lat.cell_nodes.size(); ++k) {
    if (std::abs(lat.rest_m[static_cast<std::size_t>(lat.cell_nodes[k][4])].z() - top) > eps) continue;
    const double l = lat.cell_edge_m(k);
    for (int c = 4; c < 8; ++c) f_ext[static_cast<std::size_t>(lat.cell_nodes[k][c])].z() -= p_Pa * l * l / 4.0;
  }
  test::expect_rest_on_faces(lat, f_ext, 60);
  double drop = 0.0, lateral = 0.0;
  int on_top = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& r = lat.rest_m[i];
    if (std::abs(r.z() - top) > eps) continue;
    drop += r.z() - lat.x_m[i].z();
    ++on_top;
    if (std::abs(r.x() - top) < eps && std::abs(r.y() - top) < eps) lateral = (lat.x_m[i].x() - r.x()) / r.x();
  }
  return {drop / on_top / (p_Pa * kSide_m / kE_Pa), lateral / (p_Pa / kE_Pa)};
}

TEST(RefinedCellTerms, GradedLatticeIsCompressedAsTheUniformOneAndTheSolid) {
  // springs (nu 1/4) beside the cell-term models: the supports and the load are right without any cell term
  const auto box = make_box_model(kSide_m, 4);
  for (MaterialModel model : {MaterialModel::kSprings, MaterialModel::kVolumetric, MaterialModel::kNeoHookean}) {
    const double nu = model == MaterialModel::kSprings ? 0.25 : 0.45;
    Lattice graded = graded_box(box, cell_term_spec(model, nu, 2));
    ASSERT_GT(graded.hanging.size(), 0u);
    const LatticeSpec uniform_spec = cell_term_spec(model, nu, 3);
    Lattice uniform = build_lattice(box.grid, uniform_spec, region_cells(box.grid, 3, {0, 0, 0}, 64)).value();
    const auto [g_drop, g_lateral] = compressed(graded);
    const auto [u_drop, u_lateral] = compressed(uniform);
    // the uniform lattice: the solid (E, nu) under uniform strain
    EXPECT_NEAR(u_drop, 1.0, 2e-3) << name_of(model);
    EXPECT_NEAR(u_lateral, nu, 2e-3) << name_of(model);
    // the graded one: the same (measured: within 1e-4; a cell term at the wrong edge is off by its factor)
    EXPECT_NEAR(g_drop, u_drop, 1e-3) << name_of(model);
    EXPECT_NEAR(g_lateral, u_lateral, 1e-3) << name_of(model);
  }
}

// A lattice with cells of two sizes (one coarse cell of the 2 x 2 x 2 box split), every node moved at random.
Lattice mixed_lattice(const test::BoxModel& box, MaterialModel model, double move_cells) {
  const auto cells = region_cells(box.grid, 2, {0, 0, 0}, 64);
  Lattice lat = build_refined_lattice(box.grid, cell_term_spec(model, 0.45, 2), cells, 3,
                                       std::vector<int32_t>{cells.front()}).value();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-move_cells, move_cells);
  for (auto& x : lat.x_m) x += lat.cell_m * Vec3(u(rng), u(rng), u(rng));
  return lat;
}

TEST(RefinedCellTerms, ForcesAreMinusTheEnergyGradientAndTangentsTheirDerivativeOnMixedCells) {
  const auto box = make_box_model(kSide_m, 3);
  const std::size_t probe = 0;
  {
    const Lattice lat = mixed_lattice(box, MaterialModel::kVolumetric, 0.1);
    ASSERT_GT(lat.cell_edge_m(probe), lat.cell_m);  // the coarse cells and the fine ones differ
    std::vector<Vec3> f(lat.num_nodes(), Vec3::Zero());
    add_volume_forces(lat, lat.x_m, &f);
    EXPECT_LT(test::gradient_check(lat, f, [&](const std::vector<Vec3>& x) { return volume_energy_J(lat, x); }, 1e-7).mismatch, 1e-6);
  }
  {
    // the volume term's Gauss-Newton tangent w c c^T near rest (where the left-out (J - 1) d^2 J part is small) is
    // the forces' derivative
    const Lattice lat = mixed_lattice(box, MaterialModel::kVolumetric, 1e-5);
    const std::size_t n = lat.num_nodes();
    std::vector<std::array<Vec3, 8>> c;
    std::vector<double> w;
    volume_gradients(lat, lat.x_m, &c, &w);
    std::vector<Vec3> dir(n), kp(n, Vec3::Zero()), fp(n, Vec3::Zero()), fm(n, Vec3::Zero());
    for (std::size_t i = 0; i < n; ++i) dir[i] = Vec3(std::sin(1.0 + i), std::cos(2.0 * i), 0.3 - 0.1 * std::sin(3.0 * i));
    for (std::size_t k = 0; k < c.size(); ++k) {
      double cp = 0.0;
      for (int a = 0; a < 8; ++a) cp += c[k][static_cast<std::size_t>(a)].dot(dir[static_cast<std::size_t>(lat.cell_nodes[k][a])]);
      for (int a = 0; a < 8; ++a) kp[static_cast<std::size_t>(lat.cell_nodes[k][a])] += w[k] * cp * c[k][static_cast<std::size_t>(a)];
    }
    const double h = 1e-7 * lat.cell_m;
    std::vector<Vec3> xp = lat.x_m, xm = lat.x_m;
    for (std::size_t i = 0; i < n; ++i) xp[i] += h * dir[i], xm[i] -= h * dir[i];
    add_volume_forces(lat, xp, &fp);
    add_volume_forces(lat, xm, &fm);
    double worst = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      worst = std::max(worst, (kp[i] + (fp[i] - fm[i]) / (2 * h)).norm());
      scale = std::max(scale, kp[i].norm());
    }
    EXPECT_LT(worst / scale, 1e-3);
  }
  {
    const Lattice lat = mixed_lattice(box, MaterialModel::kNeoHookean, 0.1);
    const std::size_t n = lat.num_nodes();
    std::vector<Vec3> f(n, Vec3::Zero());
    add_neo_hookean_forces(lat, lat.x_m, &f);
    EXPECT_LT(test::gradient_check(lat, f, [&](const std::vector<Vec3>& x) { return neo_hookean_energy_J(lat, x); }, 1e-7).mismatch, 1e-6);
    // the exact tangent: its product and its blocks against the forces' directional derivative
    std::vector<NeoHookeanCell> cells;
    neo_hookean_cells(lat, lat.x_m, &cells);
    std::vector<Vec3> dir(n), kp(n, Vec3::Zero()), by_blocks(n, Vec3::Zero()), fp(n, Vec3::Zero()), fm(n, Vec3::Zero());
    for (std::size_t i = 0; i < n; ++i) dir[i] = Vec3(std::sin(1.0 + i), std::cos(2.0 * i), 0.3 - 0.1 * std::sin(3.0 * i));
    add_neo_hookean_product(lat, cells, dir, &kp);
    for (std::size_t k = 0; k < cells.size(); ++k)
      for (int b = 0; b < 8; ++b)
        for (int a = 0; a < 8; ++a)
          by_blocks[static_cast<std::size_t>(lat.cell_nodes[k][b])] +=
              neo_hookean_block(lat, cells[k], b, a) * dir[static_cast<std::size_t>(lat.cell_nodes[k][a])];
    const double h = 1e-7 * lat.cell_m;
    std::vector<Vec3> xp = lat.x_m, xm = lat.x_m;
    for (std::size_t i = 0; i < n; ++i) xp[i] += h * dir[i], xm[i] -= h * dir[i];
    add_neo_hookean_forces(lat, xp, &fp);
    add_neo_hookean_forces(lat, xm, &fm);
    double worst = 0.0, worst_blocks = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      worst = std::max(worst, (kp[i] + (fp[i] - fm[i]) / (2 * h)).norm());
      worst_blocks = std::max(worst_blocks, (by_blocks[i] - kp[i]).norm());
      scale = std::max(scale, kp[i].norm());
    }
    EXPECT_LT(worst / scale, 1e-5);
    EXPECT_LT(worst_blocks / scale, 1e-12);
  }
}

}  // namespace
}  // namespace palpate
