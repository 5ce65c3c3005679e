// Analytic spring forces and stiffness blocks against two-sided finite differences.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Eigenvalues>

#include "sim/sim_test_util.h"

namespace palpate {
namespace {

// A 2^3 block (27 nodes, no fixed ones, all families) with every node moved by up to 20% of a cell.
Lattice perturbed_block() {
  LatticeSpec spec = test::spec_for(2, 40, 20, 10);
  spec.damping_Ns_per_m = 0.0;
  Lattice lat = test::make_block(2, 2, spec);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (auto& x : lat.x_m) x += lat.cell_m * Vec3(u(rng), u(rng), u(rng));
  return lat;
}

double spring_energy_J(const Lattice& lat, const std::vector<Vec3>& x) {
  double e = 0.0;
  for (const Spring& s : lat.springs) {
    const double d = (x[s.b] - x[s.a]).norm() - s.rest_m;
    e += 0.5 * s.k_N_per_m * d * d;
  }
  return e;
}

// Dense K = -df/dx assembled from the analytic blocks (no compression clamp: the exact Hessian).
Eigen::MatrixXd stiffness(const Lattice& lat) {
  const int nd = static_cast<int>(3 * lat.num_nodes());
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(nd, nd);
  for (const Spring& s : lat.springs) {
    const Mat3 b = spring_stiffness_block(s, lat.x_m[s.b] - lat.x_m[s.a], false);
    k.block<3, 3>(3 * s.a, 3 * s.a) += b;
    k.block<3, 3>(3 * s.b, 3 * s.b) += b;
    k.block<3, 3>(3 * s.a, 3 * s.b) -= b;
    k.block<3, 3>(3 * s.b, 3 * s.a) -= b;
  }
  return k;
}

TEST(FiniteDifference, SpringForcesAreMinusTheEnergyGradient) {
  const Lattice lat = perturbed_block();
  ASSERT_EQ(std::count(lat.fixed.begin(), lat.fixed.end(), 1), 0);
  std::vector<Vec3> f;
  compute_forces(lat, lat.x_m, lat.v_m_per_s, {}, &f);
  const test::GradientCheck g =
      test::gradient_check(lat, f, [&](const std::vector<Vec3>& x) { return spring_energy_J(lat, x); }, 1e-6);
  EXPECT_GT(g.largest_force_N, 0.1);
  EXPECT_LT(g.mismatch, 1e-6);
}

TEST(FiniteDifference, StiffnessMatrixIsMinusTheForceJacobianAndSymmetric) {
  Lattice lat = perturbed_block();
  const Eigen::MatrixXd k = stiffness(lat);
  EXPECT_LT((k - k.transpose()).cwiseAbs().maxCoeff(), 1e-12 * k.cwiseAbs().maxCoeff());
  const double eps = 1e-6 * lat.cell_m;
  double worst = 0.0;
  std::vector<Vec3> fp, fm;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    for (int c = 0; c < 3; ++c) {
      std::vector<Vec3> xp = lat.x_m, xm = lat.x_m;
      xp[i][c] += eps;
      xm[i][c] -= eps;
      compute_forces(lat, xp, lat.v_m_per_s, {}, &fp);
      compute_forces(lat, xm, lat.v_m_per_s, {}, &fm);
      for (std::size_t j = 0; j < lat.num_nodes(); ++j)
        for (int r = 0; r < 3; ++r) {
          const double fd = -(fp[j][r] - fm[j][r]) / (2 * eps);
          worst = std::max(worst, std::abs(fd - k(3 * j + r, 3 * i + c)));
        }
    }
  EXPECT_LT(worst / k.cwiseAbs().maxCoeff(), 1e-4);
}

TEST(FiniteDifference, ClampedBlockIsPositiveSemiDefiniteUnderCompression) {
  Spring s;
  s.rest_m = 0.01;
  s.k_N_per_m = 40.0;
  const Vec3 d(0.004, 0.001, -0.002);  // shorter than rest
  const Eigen::Vector3d ev_exact = Eigen::SelfAdjointEigenSolver<Mat3>(spring_stiffness_block(s, d, false)).eigenvalues();
  const Eigen::Vector3d ev_clamped = Eigen::SelfAdjointEigenSolver<Mat3>(spring_stiffness_block(s, d, true)).eigenvalues();
  EXPECT_LT(ev_exact.minCoeff(), 0.0);   // the exact tangent is indefinite in compression
  EXPECT_GE(ev_clamped.minCoeff(), 0.0); // the clamped one is not
}

}  // namespace
}  // namespace palpate
