// Symplectic Euler's stability limit h < 2 / w_max, found by sweeping the step on a chain and a 6^3 lattice.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "sim/sim_test_util.h"

namespace palpate {
namespace {

// Highest angular frequency of the free nodes at rest: sqrt of the largest eigenvalue of M^-1 K.
double omega_max(const Lattice& lat) {
  const std::size_t n = lat.num_nodes();
  std::vector<int> dof(n, -1);
  int nd = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!lat.fixed[i]) dof[i] = (nd += 3) - 3;
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(nd, nd);
  for (const Spring& s : lat.springs) {
    const Mat3 b = spring_stiffness_block(s, lat.x_m[s.b] - lat.x_m[s.a], false) / std::sqrt(lat.mass_kg[s.a] * lat.mass_kg[s.b]);
    const int a = dof[s.a], c = dof[s.b];
    if (a >= 0) k.block<3, 3>(a, a) += b;
    if (c >= 0) k.block<3, 3>(c, c) += b;
    if (a >= 0 && c >= 0) {
      k.block<3, 3>(a, c) -= b;
      k.block<3, 3>(c, a) -= b;
    }
  }
  return std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(k, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff());
}

// Largest energy over `steps` undamped symplectic Euler steps of size h, relative to the start.
double energy_growth(const Lattice& base, double h, int steps) {
  Lattice lat = base;
  test::kick(&lat, 1e-6);
  const double e0 = test::energy_J(lat);
  IntegratorWorkspace ws;
  double worst = 1.0;
  for (int s = 0; s < steps && test::all_finite(lat); ++s) {
    step_lattice(&lat, test::opts(IntegratorKind::kSymplecticEuler, 1), h, {}, &ws);
    worst = std::max(worst, test::energy_J(lat) / e0);
  }
  return test::all_finite(lat) ? worst : INFINITY;
}

void expect_limit_at_two_over_omega(const Lattice& lat, int steps) {
  const double w = omega_max(lat);
  const double h_crit = 2.0 / w;
  // bounded (symplectic Euler's energy oscillates by up to 1 / (1 - (h w / 2)^2), 25x at 0.98) ...
  EXPECT_LT(energy_growth(lat, 0.98 * h_crit, steps), 100.0);
  // ... and exponential growth (|lambda| = 1.5 per step for the top mode) just past the limit
  EXPECT_GT(energy_growth(lat, 1.02 * h_crit, steps), 1e6);
  // the automatic substeps use a bound that is never optimistic
  EXPECT_GE(stability_bound(lat, 1.0).omega_max_rad_per_s, w * (1 - 1e-12));
}

TEST(Cfl, SymplecticEulerStableExactlyBelowTwoOverOmegaMaxOnAChain) {
  Lattice chain = test::make_chain(20, 0.01, 30.0, 0.002, 0.0, Vec3::UnitX(), true);
  // w_max of a fixed-fixed chain of N springs: 2 sqrt(k/m) sin(pi (N-1) / (2N))
  EXPECT_NEAR(omega_max(chain), 2 * std::sqrt(30.0 / 0.002) * std::sin(M_PI * 19 / 40.0), 1e-9 * omega_max(chain));
  expect_limit_at_two_over_omega(chain, 2000);
}

TEST(Cfl, SymplecticEulerStableExactlyBelowTwoOverOmegaMaxOn6CubedLattice) {
  LatticeSpec spec = test::spec_for(4, 40, 20, 10);
  spec.damping_Ns_per_m = 0.0;
  const Lattice block = test::make_block(4, 6, spec);
  ASSERT_EQ(block.cells.size(), 216u);
  expect_limit_at_two_over_omega(block, 600);
}

// A free node without mass has no stable step at all: the bound says so (0, not NaN), and the automatic substeps
// go to their cap instead of to one, so the step's divergence check, not a silent NaN, decides.
TEST(Cfl, AMasslessFreeNodeGivesAZeroStepBoundAndTheSubstepCap) {
  LatticeSpec spec = test::spec_for(4, 40, 20, 10);
  Lattice block = test::make_block(4, 2, spec);
  std::size_t free_node = 0;
  while (block.fixed[free_node]) ++free_node;
  block.mass_kg[free_node] = 0.0;
  const StabilityBound b = stability_bound(block, 0.8);
  EXPECT_EQ(b.max_stable_dt_s, 0.0);
  StepOptions o = test::opts(IntegratorKind::kSymplecticEuler, 0);
  o.max_substeps = 37;
  EXPECT_EQ(substeps_for(block, o, 1.0 / 60.0), 37);
}

}  // namespace
}  // namespace palpate
