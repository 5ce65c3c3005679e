// The implicit solvers' linear algebra against independent references: the conjugate gradient Newton solve
// against a dense LDL^T of the same system, the closed-form backward Euler recurrence of a damped oscillator,
// the cached stability bound's invalidation, and no heap allocation in a warmed-up step.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

#include <Eigen/Dense>

#include "sim/lattice/forces.h"
#include "sim/solvers/implicit_euler.h"
#include "sim/solvers/integrator.h"
#include "sim/solvers/local_global.h"
#include "sim/solvers/stability.h"
#include "sim/sim_test_util.h"
#include "support/alloc_counter.h"

namespace palpate {
namespace {

using test::make_block;
using test::opts;

LatticeSpec pull_spec() {
  LatticeSpec s;  // bunny_pull's k, m, c
  s.node_mass_kg = 0.002;
  s.structural_N_per_m = 12.0;
  s.shear_N_per_m = 6.0;
  s.bend_N_per_m = 3.0;
  s.damping_Ns_per_m = 0.03;
  s.fix_floor = true;
  return s;
}

// A 3^3-cell block, floor fixed, nodes moved off rest by up to 0.3 cell and given random velocities.
Lattice disturbed_block() {
  Lattice lat = make_block(3, 3, pull_spec());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (!lat.fixed[i]) {
      lat.x_m[i] += 0.3 * lat.cell_m * Vec3(u(rng), u(rng), u(rng));
      lat.v_m_per_s[i] = 0.05 * Vec3(u(rng), u(rng), u(rng));
    }
  return lat;
}

// v after one Newton step of backward Euler, solved densely: (M + h D + h^2 K(x0 + h v0)) dv = h f(x0 + h v0, v0).
std::vector<Vec3> dense_newton_velocity(const Lattice& lat, double h, const std::vector<Vec3>& f_ext) {
  const std::size_t n = lat.num_nodes();
  std::vector<int> dof(n, -1);
  int nd = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!lat.fixed[i]) dof[i] = (nd += 3) - 3;
  std::vector<Vec3> x(n), f;
  for (std::size_t i = 0; i < n; ++i) x[i] = lat.fixed[i] ? lat.x_m[i] : Vec3(lat.x_m[i] + h * lat.v_m_per_s[i]);
  compute_forces(lat, x, lat.v_m_per_s, f_ext, &f);
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(nd, nd);
  Eigen::VectorXd b(nd);
  for (std::size_t i = 0; i < n; ++i)
    if (dof[i] >= 0) {
      j.block<3, 3>(dof[i], dof[i]) += lat.mass_kg[i] * Mat3::Identity();
      b.segment<3>(dof[i]) = h * f[i];
    }
  for (const Spring& s : lat.springs) {
    const Mat3 blk = h * lat.damping_Ns_per_m * Mat3::Identity() + h * h * spring_stiffness_block(s, x[s.b] - x[s.a], true);
    const int a = dof[s.a], c = dof[s.b];
    if (a >= 0) j.block<3, 3>(a, a) += blk;
    if (c >= 0) j.block<3, 3>(c, c) += blk;
    if (a >= 0 && c >= 0) {
      j.block<3, 3>(a, c) -= blk;
      j.block<3, 3>(c, a) -= blk;
    }
  }
  const Eigen::VectorXd dv = j.ldlt().solve(b);
  std::vector<Vec3> v = lat.v_m_per_s;
  for (std::size_t i = 0; i < n; ++i)
    if (dof[i] >= 0) v[i] += dv.segment<3>(dof[i]);
  return v;
}

TEST(ImplicitEuler, ConjugateGradientMatchesDenseLdltOfTheSameNewtonSystem) {
  Lattice lat = disturbed_block();
  std::vector<Vec3> f_ext(lat.num_nodes(), Vec3::Zero());
  f_ext[lat.num_nodes() - 1] = Vec3(0.0, 0.0, 0.2);
  const double h = 1.0 / 60.0;
  ImplicitEulerSolver solver;
  // two steps: the second starts from the first's update (warm start) and must be as accurate
  for (int step = 0; step < 2; ++step) {
    const std::vector<Vec3> v_ref = dense_newton_velocity(lat, h, f_ext);
    const std::vector<Vec3> v0 = lat.v_m_per_s;
    ASSERT_EQ(solver.step(&lat, h, f_ext, 1), 1);
    EXPECT_GT(solver.last_cg_iterations(), 1);  // a real iteration, not a one-block system
    EXPECT_LE(solver.last_cg_residual(), ImplicitEulerSolver::kCgTolerance);
    double err2 = 0.0, dv2 = 0.0;
    for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
      err2 += (lat.v_m_per_s[i] - v_ref[i]).squaredNorm();
      dv2 += (v_ref[i] - v0[i]).squaredNorm();
    }
    // a relative residual of 1e-6 bounds the relative error by cond(J) * 1e-6; J's condition number is < 100 here
    EXPECT_LT(std::sqrt(err2), 1e-4 * std::sqrt(dv2)) << "step " << step;
    EXPECT_GT(dv2, 0.0);
  }
}

TEST(ImplicitEuler, DampedOscillatorFollowsTheBackwardEulerRecurrence) {
  // one free node on a spring along x: backward Euler is linear here, so one Newton step is exact:
  // v' = (m v - h k (x - x_r)) / (m + h c + h^2 k), x' = x + h v'
  const double k = 100.0, m = 0.01, c = 0.05, a = 0.01, h = 1.0 / 60.0;
  Lattice lat = test::make_chain(1, a, k, m, c);
  lat.x_m[1].x() += 0.4 * a;
  double x = 0.4 * a, v = 0.0;
  IntegratorWorkspace ws;
  for (int f = 0; f < 120; ++f) {
    step_lattice(&lat, opts(IntegratorKind::kImplicitEuler), h, {}, &ws);
    v = (m * v - h * k * x) / (m + h * c + h * h * k);
    x += h * v;
    ASSERT_NEAR(lat.x_m[1].x() - a, x, 1e-12 * a) << "frame " << f;
    ASSERT_NEAR(lat.v_m_per_s[1].x(), v, 1e-12) << "frame " << f;
    ASSERT_EQ(lat.x_m[1].y(), 0.0);
  }
  EXPECT_LT(std::abs(x), 0.4 * a);  // and it did decay
}

// Mass diagonal plus the spring Laplacian of a lattice (fill-in in the factor), without the springs whose `cut`
// flag is set; spring weights vary a little so no two are alike.
Eigen::SparseMatrix<double> spring_matrix(const Lattice& lat, const std::vector<uint8_t>& cut) {
  const int n = static_cast<int>(lat.num_nodes());
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, 3.0 + 0.1 * (i % 7));
  for (std::size_t k = 0; k < lat.springs.size(); ++k) {
    if (cut[k]) continue;
    const Spring& s = lat.springs[k];
    const double w = s.k_N_per_m * (1.0 + 0.01 * static_cast<double>(k % 5));
    t.emplace_back(s.a, s.a, w);
    t.emplace_back(s.b, s.b, w);
    t.emplace_back(s.a, s.b, -w);
    t.emplace_back(s.b, s.a, -w);
  }
  Eigen::SparseMatrix<double> m(n, n);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

// The downdate column of spring k in spring_matrix (-w (e_a - e_b)(e_a - e_b)^T).
DowndateColumn spring_column(const Lattice& lat, std::size_t k) {
  const Spring& s = lat.springs[k];
  const double r = std::sqrt(s.k_N_per_m * (1.0 + 0.01 * static_cast<double>(k % 5)));
  DowndateColumn c;
  c.rows[0] = s.a;
  c.rows[1] = s.b;
  c.vals[0] = r;
  c.vals[1] = -r;
  c.count = 2;
  return c;
}

TEST(LocalGlobal, DowndateGivesTheFactorOfTheMatrixWithoutTheSprings) {
  Lattice lat = make_block(4, 4, pull_spec());
  const int n = static_cast<int>(lat.num_nodes());
  std::vector<uint8_t> cut(lat.springs.size(), 0);
  const auto full = spring_matrix(lat, cut);
  std::vector<DowndateColumn> cols;
  for (std::size_t k = 30; k < 70; ++k) {
    cut[k] = 1;
    cols.push_back(spring_column(lat, k));
  }
  const auto cut_m = spring_matrix(lat, cut);
  // 40 columns in one call: more than one batch
  ASSERT_GT(static_cast<int>(cols.size()), 2 * DowndatableLLT::kBatch);
  DowndatableLLT llt;
  llt.compute(full);
  ASSERT_EQ(llt.info(), Eigen::Success);
  ASSERT_TRUE(llt.downdate(cols.data(), static_cast<int>(cols.size())));
  // the downdated factor solves the cut matrix as a fresh factorisation does
  Eigen::MatrixX3d b = Eigen::MatrixX3d::Random(n, 3);
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> fresh(cut_m);
  const Eigen::MatrixX3d x_down = llt.solve(b), x_fresh = fresh.solve(b);
  EXPECT_LT((x_down - x_fresh).norm(), 1e-12 * x_fresh.norm());
  EXPECT_LT((cut_m * x_down - b).norm(), 1e-12 * b.norm());
  // and it no longer solves the full one
  EXPECT_GT((full * x_down - b).norm(), 1e-3 * b.norm());
  // taking out more than a diagonal holds leaves no positive definite matrix: refused, and the scratch is left
  // clean (the next downdate of a refactored factor is exact again)
  DowndateColumn too_much;
  too_much.rows[0] = 5;
  too_much.vals[0] = 2.0 * std::sqrt(cut_m.coeff(5, 5));
  too_much.count = 1;
  const DowndateColumn bad[2] = {cols[0], too_much};
  EXPECT_FALSE(llt.downdate(bad, 2));
  llt.compute(full);
  ASSERT_TRUE(llt.downdate(cols.data(), static_cast<int>(cols.size())));
  EXPECT_LT((llt.solve(b) - x_fresh).norm(), 1e-12 * x_fresh.norm());
}

TEST(LocalGlobal, ThreeColumnSolveIsEigensSolveBitForBit) {
  // the fused three-column solve the step uses does solve()'s arithmetic in solve()'s order: equal to the last bit,
  // with zero entries and rows in the right-hand side, after a downdate; and it leaves x alone when the
  // factorisation failed
  Lattice lat = make_block(4, 4, pull_spec());
  const int n = static_cast<int>(lat.num_nodes());
  std::vector<uint8_t> none(lat.springs.size(), 0);
  DowndatableLLT llt;
  llt.compute(spring_matrix(lat, none));
  ASSERT_EQ(llt.info(), Eigen::Success);
  Eigen::MatrixX3d b = Eigen::MatrixX3d::Random(n, 3);
  for (int i = 0; i < n; i += 5) b(i, i % 3) = (i % 2) ? 0.0 : -0.0;
  for (int i = 0; i < n; i += 17) b.row(i).setZero();
  std::vector<double> scratch;
  auto check = [&](const char* what) {
    const Eigen::MatrixX3d expected = llt.solve(b);
    Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> rows = b, x(n, 3);
    x.setConstant(7.0);
    llt.solve_rows3(rows.data(), x.data(), &scratch);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(std::memcmp(&x(i, c), &expected(i, c), sizeof(double)), 0)
            << what << " row " << i << " column " << c << ": " << x(i, c) << " vs " << expected(i, c);
      }
  };
  check("fresh factor");
  std::vector<DowndateColumn> cols;
  for (std::size_t k = 3; k < lat.springs.size(); k += 11) cols.push_back(spring_column(lat, k));
  ASSERT_TRUE(llt.downdate(cols.data(), static_cast<int>(cols.size())));
  check("downdated factor");
  Eigen::SparseMatrix<double> indefinite(2, 2);
  indefinite.insert(0, 0) = -1.0;
  indefinite.insert(1, 1) = 1.0;
  llt.compute(indefinite);
  ASSERT_NE(llt.info(), Eigen::Success);
  std::vector<double> in = {1, 2, 3, 4, 5, 6}, out(6, 7.0);
  llt.solve_rows3(in.data(), out.data(), &scratch);
  EXPECT_EQ(out, std::vector<double>(6, 7.0));
}

TEST(LocalGlobal, ADowndateOfManyColumnsIsTheirRankOneDowndatesInOrder) {
  // one sweep per batch over the union of the paths does the same arithmetic as one sweep per column: bit for bit
  Lattice lat = make_block(4, 4, pull_spec());
  const std::vector<uint8_t> none(lat.springs.size(), 0);
  std::vector<DowndateColumn> cols;
  for (std::size_t k = 5; k < lat.springs.size(); k += 13) cols.push_back(spring_column(lat, k));
  ASSERT_GT(static_cast<int>(cols.size()), DowndatableLLT::kBatch);
  DowndatableLLT together, one_by_one;
  together.compute(spring_matrix(lat, none));
  one_by_one.compute(spring_matrix(lat, none));
  ASSERT_TRUE(together.downdate(cols.data(), static_cast<int>(cols.size())));
  for (const DowndateColumn& c : cols) ASSERT_TRUE(one_by_one.downdate(&c, 1));
  const auto& a = together.matrixL().nestedExpression();
  const auto& b = one_by_one.matrixL().nestedExpression();
  ASSERT_EQ(a.nonZeros(), b.nonZeros());
  for (Eigen::Index p = 0; p < a.nonZeros(); ++p) ASSERT_EQ(a.valuePtr()[p], b.valuePtr()[p]) << "entry " << p;
}

TEST(LocalGlobal, ManyCutsDowndatedSolveAsAFreshFactorisationOfTheCutMatrix) {
  // an 8^3 block cut in 25 steps of growing size (1 to 49 springs, 625 of its 9144): after each, the
  // downdated factor solves the cut matrix as a fresh factorisation of it does
  Lattice lat = make_block(5, 8, pull_spec());
  const int n = static_cast<int>(lat.num_nodes());
  std::vector<uint8_t> cut(lat.springs.size(), 0);
  DowndatableLLT llt;
  llt.compute(spring_matrix(lat, cut));
  ASSERT_EQ(llt.info(), Eigen::Success);
  const Eigen::MatrixX3d b = Eigen::MatrixX3d::Random(n, 3);
  std::size_t next = 0;
  int total = 0;
  for (int step = 0; step < 25; ++step) {
    std::vector<DowndateColumn> cols;
    for (int i = 0; i <= 2 * step && next < lat.springs.size(); ++i, next += 4) {
      cut[next] = 1;
      cols.push_back(spring_column(lat, next));
    }
    total += static_cast<int>(cols.size());
    ASSERT_TRUE(llt.downdate(cols.data(), static_cast<int>(cols.size()))) << "step " << step;
    const auto m = spring_matrix(lat, cut);
    const Eigen::MatrixX3d x_fresh = Eigen::SimplicialLLT<Eigen::SparseMatrix<double>>(m).solve(b);
    const Eigen::MatrixX3d x_down = llt.solve(b);
    ASSERT_LT((x_down - x_fresh).norm(), 1e-10 * x_fresh.norm()) << "step " << step;
    ASSERT_LT((m * x_down - b).norm(), 1e-10 * b.norm()) << "step " << step;
  }
  EXPECT_EQ(total, 625);
}

// Mean over the springs of the factor entries on the elimination-tree path from the first of the spring's ends
// (parent of column k: its first row below the diagonal), from the factor and ordering alone.
template <typename Solver>
double mean_path_entries(const Solver& llt, const Lattice& lat) {
  const auto& l = llt.matrixL().nestedExpression();
  const int* lp = l.outerIndexPtr();
  const int* li = l.innerIndexPtr();
  const auto& p = llt.permutationP().indices();
  double sum = 0.0;
  for (const Spring& s : lat.springs) {
    for (int k = std::min(p[s.a], p[s.b]); k >= 0; k = lp[k + 1] - lp[k] > 1 ? li[lp[k] + 1] : -1)
      sum += lp[k + 1] - lp[k];
  }
  return sum / static_cast<double>(lat.springs.size());
}

TEST(LocalGlobal, NestedDissectionShortensTheDowndatePathsOfALattice) {
  Lattice lat = make_block(5, 10, pull_spec());
  const auto m = spring_matrix(lat, std::vector<uint8_t>(lat.springs.size(), 0));
  // the ordering is a permutation of the rows
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> perm;
  nested_dissection(m, &perm);
  std::vector<int> rows(perm.indices().data(), perm.indices().data() + perm.size());
  std::sort(rows.begin(), rows.end());
  ASSERT_EQ(static_cast<Eigen::Index>(rows.size()), m.rows());
  for (std::size_t i = 0; i < rows.size(); ++i) ASSERT_EQ(rows[i], static_cast<int>(i));
  DowndatableLLT nd;
  nd.compute(m);
  ASSERT_EQ(nd.info(), Eigen::Success);
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> amd(m);
  ASSERT_EQ(amd.info(), Eigen::Success);
  const double nd_path = mean_path_entries(nd, lat), amd_path = mean_path_entries(amd, lat);
  std::printf("mean downdate path: nested dissection %.0f, minimum degree %.0f entries\n", nd_path, amd_path);
  EXPECT_LT(nd_path, 0.9 * amd_path);  // 0.86 on this block
  // a one-row matrix (nothing for METIS to dissect) still gets an ordering
  Eigen::SparseMatrix<double> one(1, 1);
  one.insert(0, 0) = 2.0;
  DowndatableLLT tiny;
  tiny.compute(one);
  ASSERT_EQ(tiny.info(), Eigen::Success);
  EXPECT_DOUBLE_EQ(tiny.solve(Eigen::VectorXd::Constant(1, 4.0))(0), 2.0);
}

TEST(LocalGlobal, CutDowndatesTheFactorToTheSameStep) {
  Lattice lat = disturbed_block();
  LocalGlobalSolver kept;
  ASSERT_EQ(kept.step(&lat, 1.0 / 60.0, {}, 5), 5);
  // a cut: springs removed, the lattice touched; the kept solver downdates its factor, one spring at a time
  // (four springs with a free end, taken out keeping the order as cut_springs does)
  std::vector<Spring> kept_springs;
  int64_t in_matrix = 0;
  for (const Spring& sp : lat.springs) {
    const bool free_end = !(lat.fixed[sp.a] && lat.fixed[sp.b]);
    if (free_end && in_matrix < 4 && (sp.a % 7 == 3)) ++in_matrix;
    else kept_springs.push_back(sp);
  }
  ASSERT_EQ(in_matrix, 4);
  lat.springs = kept_springs;
  lat.touch();
  Lattice fresh_lat = lat;
  LocalGlobalSolver fresh;
  ASSERT_EQ(kept.step(&lat, 1.0 / 60.0, {}, 5), 5);
  ASSERT_EQ(fresh.step(&fresh_lat, 1.0 / 60.0, {}, 5), 5);
  EXPECT_EQ(kept.analyses(), 1);
  EXPECT_EQ(kept.factorizations(), 1);
  EXPECT_EQ(kept.downdates(), in_matrix);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    ASSERT_LT((lat.x_m[i] - fresh_lat.x_m[i]).norm(), 1e-12 * lat.cell_m) << "node " << i;
  // a change that is not a removal (a stiffer spring) refactors
  lat.springs[3].k_N_per_m *= 2.0;
  lat.touch();
  fresh_lat = lat;
  ASSERT_EQ(kept.step(&lat, 1.0 / 60.0, {}, 5), 5);
  ASSERT_EQ(LocalGlobalSolver().step(&fresh_lat, 1.0 / 60.0, {}, 5), 5);
  EXPECT_EQ(kept.factorizations(), 2);
  EXPECT_EQ(kept.downdates(), in_matrix);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    ASSERT_LT((lat.x_m[i] - fresh_lat.x_m[i]).norm(), 1e-12 * lat.cell_m) << "node " << i;
}

TEST(LocalGlobal, CutDearerToDowndateThanToRefactorRefactors) {
  Lattice lat = disturbed_block();
  LocalGlobalSolver kept;
  ASSERT_EQ(kept.step(&lat, 1.0 / 60.0, {}, 5), 5);
  // 30 of this small lattice's springs: their downdate paths touch more than 0.3 of a factorisation's entries
  lat.springs.erase(lat.springs.begin() + 10, lat.springs.begin() + 40);
  lat.touch();
  ASSERT_EQ(kept.step(&lat, 1.0 / 60.0, {}, 5), 5);
  EXPECT_EQ(kept.factorizations(), 2);
  EXPECT_EQ(kept.downdates(), 0);
}

TEST(LocalGlobal, CutPastTheDowndateLimitRefactorsInTheAnalysedPatternToTheSameStep) {
  Lattice lat = disturbed_block();
  LocalGlobalSolver kept;
  kept.set_max_downdates(10);
  ASSERT_EQ(kept.step(&lat, 1.0 / 60.0, {}, 5), 5);
  // 30 springs removed, more than the limit: a numeric refactorisation without a new analysis
  lat.springs.erase(lat.springs.begin() + 10, lat.springs.begin() + 40);
  lat.touch();
  Lattice fresh_lat = lat;
  LocalGlobalSolver fresh;
  ASSERT_EQ(kept.step(&lat, 1.0 / 60.0, {}, 5), 5);
  ASSERT_EQ(fresh.step(&fresh_lat, 1.0 / 60.0, {}, 5), 5);
  EXPECT_EQ(kept.analyses(), 1);
  EXPECT_EQ(kept.factorizations(), 2);
  EXPECT_EQ(kept.downdates(), 0);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    ASSERT_LT((lat.x_m[i] - fresh_lat.x_m[i]).norm(), 1e-12 * lat.cell_m) << "node " << i;
  // a new step size refactors in the same pattern too
  ASSERT_EQ(kept.step(&lat, 1.0 / 120.0, {}, 1), 1);
  EXPECT_EQ(kept.analyses(), 1);
  EXPECT_EQ(kept.factorizations(), 3);
  // a new free-node set (a node released) is a new pattern: analysed again
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (lat.fixed[i]) {
      lat.fixed[i] = 0;
      break;
    }
  lat.touch();
  ASSERT_EQ(kept.step(&lat, 1.0 / 120.0, {}, 1), 1);
  EXPECT_EQ(kept.analyses(), 2);
}

TEST(StabilityCache, BoundFollowsStiffnessOnTouchAndOnlyThen) {
  Lattice lat = make_block(3, 3, pull_spec());
  IntegratorWorkspace ws;
  const StabilityBound b1 = cached_stability_bound(lat, &ws);
  EXPECT_DOUBLE_EQ(b1.max_stable_dt_s, stability_bound(lat, 0.8).max_stable_dt_s);
  const StepOptions o = opts(IntegratorKind::kSymplecticEuler);
  const int sub1 = substeps_for(lat, o, 1.0 / 60.0, &ws);
  for (Spring& s : lat.springs) s.k_N_per_m *= 4.0;
  // not touched: the cache is what it was (the contract: changes to k, m or topology call touch())
  EXPECT_DOUBLE_EQ(cached_stability_bound(lat, &ws).omega_max_rad_per_s, b1.omega_max_rad_per_s);
  lat.touch();
  const StabilityBound b2 = cached_stability_bound(lat, &ws);
  EXPECT_NEAR(b2.omega_max_rad_per_s, 2.0 * b1.omega_max_rad_per_s, 1e-9 * b1.omega_max_rad_per_s);
  EXPECT_DOUBLE_EQ(b2.max_stable_dt_s, stability_bound(lat, 0.8).max_stable_dt_s);
  EXPECT_GT(substeps_for(lat, o, 1.0 / 60.0, &ws), sub1);
  EXPECT_EQ(substeps_for(lat, o, 1.0 / 60.0, &ws), substeps_for(lat, o, 1.0 / 60.0));
}

TEST(StepAllocations, WarmedUpStepsDoNotAllocate) {
  for (IntegratorKind kind : {IntegratorKind::kSymplecticEuler, IntegratorKind::kImplicitEuler,
                              IntegratorKind::kLocalGlobal}) {
    Lattice lat = disturbed_block();
    std::vector<Vec3> f_ext(lat.num_nodes(), Vec3(0.0, 0.0, 0.01));
    IntegratorWorkspace ws;
    const StepOptions o = opts(kind);
    for (int f = 0; f < 3; ++f) step_lattice(&lat, o, 1.0 / 60.0, f_ext, &ws);  // warm-up: caches and buffers
    int64_t allocs = 0;
    {
      test::AllocationGuard guard;
      for (int f = 0; f < 20; ++f) step_lattice(&lat, o, 1.0 / 60.0, f_ext, &ws);
      allocs = guard.count();
    }
    EXPECT_EQ(allocs, 0) << integrator_name(kind);
  }
}

}  // namespace
}  // namespace palpate
