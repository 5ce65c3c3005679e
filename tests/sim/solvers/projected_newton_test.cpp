// The projected Newton step of implicit Euler (ImplicitEulerSolver::projected_step): the Neo-Hookean cell's
// projected Hessian against the stress's derivative, the energy below kMinCellJ against the forces, the step against
// converged backward Euler where nothing needs projecting (a deep press that needs it: tests/runtime/record/recording_outcome_test.cpp).

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "sim/solvers/implicit_euler.h"
#include "sim/solvers/integrator.h"
#include "sim/material/neo_hookean_term.h"
#include "sim/reference/reference_cases.h"
#include "sim/material/volume_term.h"
#include "sim/sim_test_util.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

MaterialSpec tissue(double nu) {
  MaterialSpec m = test::soft_material(nu, MaterialModel::kNeoHookean);
  m.young_modulus_Pa = 1e4;
  m.stiffness_damping_s = 1e-3;
  return m;
}

// d P / d F by central differences of the stress, on vec F (column-major)
Mat9 stress_derivative(double mu, double lambda, const Mat3& f) {
  Mat9 d;
  const double h = 1e-7;
  for (int c = 0; c < 9; ++c) {
    Mat3 fp = f, fm = f;
    fp(c % 3, c / 3) += h;
    fm(c % 3, c / 3) -= h;
    const Mat3 dp = (neo_hookean_stress_Pa(mu, lambda, fp) - neo_hookean_stress_Pa(mu, lambda, fm)) / (2 * h);
    d.col(c) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dp.data());
  }
  return d;
}

// Where the stress's derivative is positive definite (a cell stretched and turned) the projected Hessian is that
// derivative; squashed and inverted it stays symmetric and positive semi-definite, where the derivative is not (the
// Neo-Hookean tangent has a negative twist stiffness mu - (mu - lambda ln J) / (s_i s_j) once a pair of axes is
// shortened enough).
TEST(ProjectedNewton, TheCellsHessianIsTheStressDerivativeWherePositiveAndPositiveEverywhere) {
  const double mu = 3448.0, lambda = 31034.0;  // E 10 kPa, nu 0.45
  const Mat3 rot = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Mat3 mild = rot * (Mat3() << 1.1, 0.05, 0.0, 0.02, 1.05, 0.03, -0.02, 0.0, 1.08).finished();  // stretched
  const Mat9 exact = stress_derivative(mu, lambda, mild);
  ASSERT_GT(Eigen::SelfAdjointEigenSolver<Mat9>(0.5 * (exact + exact.transpose())).eigenvalues().minCoeff(), 0.0);
  EXPECT_LT((neo_hookean_projected_hessian(mu, lambda, mild) - exact).norm(), 1e-5 * exact.norm());

  const Mat3 squashed = rot * Vec3(1.3, 1.25, 0.05).asDiagonal();                   // J 0.08: twist modes negative
  const Mat3 inverted = rot * (Mat3() << 1.1, 0.2, 0.0, 0.0, 0.9, 0.1, 0.0, 0.0, -0.3).finished();  // J < 0
  for (const Mat3& f : {squashed, inverted}) {
    const Mat9 d = stress_derivative(mu, lambda, f);
    EXPECT_LT(Eigen::SelfAdjointEigenSolver<Mat9>(0.5 * (d + d.transpose())).eigenvalues().minCoeff(), 0.0)
        << "the case needs projecting";
    const Mat9 h = neo_hookean_projected_hessian(mu, lambda, f);
    EXPECT_LT((h - h.transpose()).norm(), 1e-12 * h.norm());
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat9>(h).eigenvalues().minCoeff(), -1e-9 * h.norm());
  }
}

// A cell turned inside out is pushed back by the stress at kMinCellJ; the energy continues linearly in J there, so the
// forces stay its gradient (the line search of the projected step compares energies).
TEST(ProjectedNewton, AnInvertedCellsForcesAreMinusItsEnergysGradient) {
  Lattice lat = box_lattice(tissue(0.45), 0.02, 2, {1, 1, 1}).value();
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (lat.rest_m[i].z() > 0.5 * lat.cell_m) lat.x_m[i].z() -= 1.3 * lat.cell_m;  // the top face below the bottom
  lat.x_m[0] += Vec3(0.1, -0.05, 0.02) * lat.cell_m;
  const Mat3 f = cell_deformation_gradient(lat.x_m, lat.cell_nodes[0], lat.cell_edge_m(0));
  ASSERT_LT(f.determinant(), 0.0);
  std::vector<Vec3> force(lat.num_nodes(), Vec3::Zero());
  add_neo_hookean_forces(lat, lat.x_m, &force);
  const test::GradientCheck g =
      test::gradient_check(lat, force, [&](const std::vector<Vec3>& x) { return neo_hookean_energy_J(lat, x); }, 1e-6);
  EXPECT_LT(g.mismatch, 1e-5) << "largest force " << g.largest_force_N << " N";
}

// A disturbed Neo-Hookean block with nothing to project: the projected step reaches the backward Euler step that
// Newton's method converges to (the line search's potential has the residual as its gradient, or it would stall).
TEST(ProjectedNewton, WhereNothingNeedsProjectingItIsConvergedBackwardEuler) {
  Lattice lat = box_lattice(tissue(0.45), 0.02, 4, {2, 2, 2}).value();
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    if (lat.rest_m[i].z() < 1e-9) lat.fixed[i] = 1;
    else lat.v_m_per_s[i] = Vec3(0.4 * std::sin(1.0 + i), 0.3 * std::cos(2.0 * i), -0.5);
  }
  const std::vector<Vec3> load;
  Lattice newton = lat, projected = lat;
  ImplicitEulerSolver a, b;
  const double h = 1e-3;  // the mass term keeps backward Euler's matrix positive definite at this step
  ASSERT_GT(a.step(&newton, h, load, 30), 1);
  ASSERT_GT(b.projected_step(&projected, h, load, 30), 1);
  double worst = 0.0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) worst = std::max(worst, (newton.x_m[i] - projected.x_m[i]).norm());
  EXPECT_LT(worst, 1e-6 * lat.cell_m);
}

// A realtime frame's deadline (StepOptions::deadline_ns) already past: a block whose top face was pushed below its
// bottom (every cell inverted) fails the whole implicit step; the retries are cut short — no split is finished, and
// projected Newton takes its first step and stops — and the step ends there, out of time, the lattice finite and
// lower in its substep's potential than where it started. Without a deadline the same step takes its retries in full.
TEST(ProjectedNewton, PastTheDeadlineAFailedStepTakesOneProjectedStepAndEnds) {
  Lattice squashed = box_lattice(tissue(0.45), 0.02, 4, {2, 2, 2}).value();
  for (std::size_t i = 0; i < squashed.num_nodes(); ++i) {
    if (squashed.rest_m[i].z() < 1e-9) squashed.fixed[i] = 1;
    else squashed.x_m[i].z() -= 1.3 * squashed.rest_m[i].z();
  }
  StepOptions opts;
  opts.kind = IntegratorKind::kImplicitEuler;
  opts.substeps = 1;
  const std::vector<Vec3> load;
  Lattice late = squashed, free = squashed;
  IntegratorWorkspace ws_late, ws_free;
  StepOptions past = opts;
  past.deadline_ns = 1;  // long gone
  const StepReport a = step_lattice(&late, past, 1.0 / 60.0, load, &ws_late);
  const StepReport b = step_lattice(&free, opts, 1.0 / 60.0, load, &ws_free);
  ASSERT_EQ(b.implicit_splits + b.projected_steps > 0, true) << "the case needs the retries";
  EXPECT_TRUE(a.out_of_time);
  EXPECT_FALSE(b.out_of_time);
  EXPECT_TRUE(a.finite);
  EXPECT_TRUE(a.solver_ok) << "out of time is not a failed solver: no explicit fallback";
  EXPECT_EQ(a.projected_steps, 1);
  EXPECT_LT(a.cg_iterations, b.cg_iterations);
  double moved = 0.0;
  for (std::size_t i = 0; i < late.num_nodes(); ++i) moved = std::max(moved, (late.x_m[i] - squashed.x_m[i]).norm());
  EXPECT_GT(moved, 0.0) << "the step made no progress";
  std::printf("[ figures ] out of time: %d CG iterations, %d projected; in full: %d CG iterations, %d splits, %d projected\n",
              a.cg_iterations, a.projected_steps, b.cg_iterations, b.implicit_splits, b.projected_steps);
}

}  // namespace
}  // namespace palpate
