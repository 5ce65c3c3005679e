#include "sim/lattice/lattice.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "sim/lattice/forces.h"
#include "sim/solvers/integrator.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

using test::make_box_model;
using test::spec_for;

// A full n x n x n block of cells: the box fills the cube at level 3 (4 cells per axis).
Lattice full_block(const LatticeSpec& spec) {
  static const auto box = make_box_model(0.04, 3);
  return build_lattice(box.grid, spec, region_cells(box.grid, spec.level, {1, 1, 1}, 64)).value();
}

TEST(Lattice, SpringCountsPerFamilyMatchFormulasFor4x4x4Block) {
  const int n = 4;  // cells per axis
  const Lattice lat = full_block(spec_for(3, 40, 20, 10));
  EXPECT_EQ(lat.cells.size(), 64u);
  EXPECT_EQ(lat.num_nodes(), static_cast<std::size_t>((n + 1) * (n + 1) * (n + 1)));
  // structural: 3 axes x n edges x (n+1)^2 lines
  EXPECT_EQ(lat.springs_per_family[0], 3 * n * (n + 1) * (n + 1));
  // shear: 2 diagonals on each of 3 n (n+1) n faces, plus 4 body diagonals per cell
  EXPECT_EQ(lat.springs_per_family[1], 2 * 3 * n * n * (n + 1) + 4 * n * n * n);
  // bend: 3 axes x (n-1) skip-one pairs x (n+1)^2 lines
  EXPECT_EQ(lat.springs_per_family[2], 3 * (n - 1) * (n + 1) * (n + 1));
  EXPECT_EQ(lat.springs.size(), static_cast<std::size_t>(300 + 736 + 225));
}

TEST(Lattice, FamiliesSwitchOffIndependently) {
  EXPECT_EQ(full_block(spec_for(3, 40, 0, 0)).springs.size(), 300u);
  EXPECT_EQ(full_block(spec_for(3, 0, 20, 0)).springs.size(), 736u);
  EXPECT_EQ(full_block(spec_for(3, 0, 0, 10)).springs.size(), 225u);
}

TEST(Lattice, RestLengthsAreCellMultiples) {
  const Lattice lat = full_block(spec_for(3, 40, 20, 10));
  for (const Spring& s : lat.springs) {
    const double r = s.rest_m / lat.cell_m;
    switch (s.family) {
      case SpringFamily::kStructural: EXPECT_NEAR(r, 1.0, 1e-12); break;
      case SpringFamily::kShear: EXPECT_TRUE(std::abs(r - std::sqrt(2.0)) < 1e-12 || std::abs(r - std::sqrt(3.0)) < 1e-12); break;
      case SpringFamily::kBend: EXPECT_NEAR(r, 2.0, 1e-12); break;
    }
  }
}

TEST(Lattice, RegionBorderNodesAreFixedAndInteriorFree) {
  const auto box = make_box_model(0.04, 3);
  // a 3x3x3 region around cell (1,1,1) of the 4^3 block: its faces toward x=3, y=3, z=3 touch outside cells
  auto spec = spec_for(3, 40, 20, 10);
  const Lattice lat = build_lattice(box.grid, spec, region_cells(box.grid, 3, {1, 1, 1}, 1)).value();
  EXPECT_EQ(lat.cells.size(), 27u);
  int fixed = 0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    const Vec3 g = (lat.rest_m[i] - box.grid.cube().min_m) / lat.cell_m;
    const bool on_inner_border = std::lround(g.x()) == 3 || std::lround(g.y()) == 3 || std::lround(g.z()) == 3;
    EXPECT_EQ(lat.fixed[i] != 0, on_inner_border) << "node " << i;
    fixed += lat.fixed[i];
  }
  EXPECT_EQ(fixed, 64 - 27);  // 4^3 nodes, of which the 3^3 away from the border are free
}

TEST(Lattice, AtRestWithGravityOffNothingMoves) {
  Lattice lat = full_block(spec_for(3, 40, 20, 10));
  IntegratorWorkspace ws;
  for (auto kind : {IntegratorKind::kSymplecticEuler, IntegratorKind::kExplicitEuler}) {
    for (int f = 0; f < 120; ++f) step_lattice(&lat, kind, 1.0 / 60.0, 256, {}, &ws);
    for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
      EXPECT_EQ(lat.x_m[i], lat.rest_m[i]);
      EXPECT_EQ(lat.v_m_per_s[i], Vec3::Zero());
    }
  }
}

TEST(Lattice, PulledCellReturnsToRestWhenReleased) {
  const auto box = make_box_model(0.04, 3);
  auto spec = spec_for(3, 40, 20, 10);
  spec.fix_floor = true;
  Lattice lat = build_lattice(box.grid, spec, region_cells(box.grid, 3, {1, 1, 1}, 64)).value();
  // pull the top corner node of the block for half a second, then let go
  std::size_t top = 0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (lat.rest_m[i].sum() > lat.rest_m[top].sum()) top = i;
  std::vector<Vec3> f(lat.num_nodes(), Vec3::Zero());
  f[top] = Vec3(0.3, 0.2, 0.5);
  IntegratorWorkspace ws;
  for (int frame = 0; frame < 30; ++frame) step_lattice(&lat, IntegratorKind::kSymplecticEuler, 1.0 / 60.0, 256, f, &ws);
  const double pulled = (lat.x_m[top] - lat.rest_m[top]).norm();
  EXPECT_GT(pulled, 0.05 * lat.cell_m);
  for (int frame = 0; frame < 600; ++frame) step_lattice(&lat, IntegratorKind::kSymplecticEuler, 1.0 / 60.0, 256, {}, &ws);
  double worst = 0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) worst = std::max(worst, (lat.x_m[i] - lat.rest_m[i]).norm());
  EXPECT_LT(worst, 1e-4 * lat.cell_m);
}

TEST(Lattice, SymplecticSubstepsFollowTheStabilityBound) {
  Lattice lat = full_block(spec_for(3, 40, 20, 10));
  const StabilityBound b = stability_bound(lat, 0.8);
  EXPECT_GT(b.omega_max_rad_per_s, 0.0);
  EXPECT_LE(b.max_stable_dt_s * b.max_stable_dt_s * b.omega_max_rad_per_s * b.omega_max_rad_per_s +
                2 * b.max_stable_dt_s * b.damping_rate_per_s,
            3.2 + 1e-9);
  // independent of the bound's formula: the largest natural frequency of the linearised lattice at rest,
  // sqrt(max eig M^-1 K) over the free nodes (dense eigen-solve); a Gershgorin bound is never below it, and for
  // a cubic lattice not far above it
  std::vector<int> dof(lat.num_nodes(), -1);
  int n = 0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (!lat.fixed[i]) dof[i] = 3 * n++;
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (const Spring& sp : lat.springs) {
    const Vec3 u = (lat.rest_m[sp.b] - lat.rest_m[sp.a]).normalized();
    const Mat3 kk = sp.k_N_per_m * u * u.transpose();
    const int a = dof[sp.a], c = dof[sp.b];
    if (a >= 0) k.block<3, 3>(a, a) += kk;
    if (c >= 0) k.block<3, 3>(c, c) += kk;
    if (a >= 0 && c >= 0) {
      k.block<3, 3>(a, c) -= kk;
      k.block<3, 3>(c, a) -= kk;
    }
  }
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (dof[i] >= 0) k.block(dof[i], 0, 3, 3 * n) /= lat.mass_kg[i];  // M^-1 K (equal masses: still symmetric)
  const double omega_true = std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(k).eigenvalues().maxCoeff());
  EXPECT_GE(b.omega_max_rad_per_s, omega_true);
  EXPECT_LE(b.omega_max_rad_per_s, 2.0 * omega_true);
  IntegratorWorkspace ws;
  const StepReport r = step_lattice(&lat, IntegratorKind::kSymplecticEuler, 1.0 / 60.0, 100000, {}, &ws);
  EXPECT_EQ(r.substeps, static_cast<int>(std::ceil((1.0 / 60.0) / b.max_stable_dt_s)));
  // and the substeps taken hold symplectic Euler's own limit h < 2 / omega for the true frequency
  EXPECT_LT((1.0 / 60.0) / r.substeps, 2.0 / omega_true);
}

TEST(Lattice, MaxStrainIsTheLargestStretchOrCompression) {
  LatticeSpec spec = spec_for(3, 40, 20, 10);
  Lattice lat = full_block(spec);
  // the direct |l - l0| / l0 over every spring, for a stretched and then a compressed extreme
  auto direct = [](const Lattice& l) {
    double m = 0.0;
    for (const Spring& s : l.springs) m = std::max(m, std::abs((l.x_m[s.b] - l.x_m[s.a]).norm() - s.rest_m) / s.rest_m);
    return m;
  };
  EXPECT_NEAR(max_strain(lat), 0.0, 1e-12);
  lat.x_m[5] += Vec3(0.3, 0.1, 0.0) * lat.cell_m;
  EXPECT_NEAR(max_strain(lat), direct(lat), 1e-12);
  lat.x_m[9] += Vec3(0.0, 0.0, 0.8) * lat.cell_m;  // nearly collapses a spring: compression is the extreme
  EXPECT_GT(direct(lat), 0.5);
  EXPECT_NEAR(max_strain(lat), direct(lat), 1e-12);
}

TEST(Lattice, ZeroLengthSpringGivesNoNaN) {
  Lattice lat = full_block(spec_for(3, 40, 20, 10));
  // collapse every node onto one point
  for (auto& x : lat.x_m) x = Vec3(0.001, 0.002, 0.003);
  std::vector<Vec3> f;
  compute_forces(lat, lat.x_m, lat.v_m_per_s, {}, &f);
  for (const Vec3& v : f) EXPECT_TRUE(v.allFinite());
}

}  // namespace
}  // namespace palpate
