// The lattice's static compliance at a point (used by the servo between frames): analytic cases and the
// singular ones (nothing fixed, a piece cut free) reported, never returned as a number.
#include "sim/contact/contact_compliance.h"

#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "sim/sim_test_util.h"

namespace palpate {
namespace {

// One free node at the origin held by six axis springs to fixed nodes: K = 2 k I, so C = I / (2k).
Lattice star(double k) {
  Lattice lat;
  lat.rest_m = {Vec3::Zero(), Vec3::UnitX(), -Vec3::UnitX(), Vec3::UnitY(), -Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
  lat.x_m = lat.rest_m;
  lat.v_m_per_s.assign(7, Vec3::Zero());
  lat.mass_kg.assign(7, 1.0);
  lat.fixed = {0, 1, 1, 1, 1, 1, 1};
  for (int32_t j = 1; j < 7; ++j) {
    Spring s;
    s.a = 0;
    s.b = j;
    s.rest_m = 1.0;
    s.k_N_per_m = k;
    lat.springs.push_back(s);
  }
  return lat;
}

// A point force at the star's centre node on `lat`, which holds a piece free of every fixed node: no compliance
// exists, compute() says so and leaves c untouched.
void expect_no_compliance_at_the_centre(const Lattice& lat) {
  PointWeights w;
  w.count = 1;
  w.node[0] = 0;
  w.weight[0] = 1.0;
  ContactCompliance cc;
  Mat3 c = Mat3::Constant(7.0);
  EXPECT_FALSE(cc.compute(lat, w, true, &c));
  EXPECT_EQ(c, Mat3::Constant(7.0));
}

TEST(ContactCompliance, StarOfSpringsHasAnalyticCompliance) {
  const Lattice lat = star(50.0);
  PointWeights w;
  w.count = 1;
  w.node[0] = 0;
  w.weight[0] = 1.0;
  ContactCompliance cc;
  Mat3 c;
  ASSERT_TRUE(cc.compute(lat, w, true, &c));
  EXPECT_LT((c - Mat3::Identity() / 100.0).norm(), 1e-12);
  // a point shared half with a fixed node feels half the force: C scales by 1/4
  w.count = 2;
  w.weight[0] = 0.5;
  w.node[1] = 3;
  w.weight[1] = 0.5;
  ASSERT_TRUE(cc.compute(lat, w, false, &c));
  EXPECT_LT((c - Mat3::Identity() / 400.0).norm(), 1e-12);
}

TEST(ContactCompliance, FreeFloatingLatticeIsReportedNotNaN) {
  Lattice lat = star(50.0);
  lat.fixed.assign(7, 0);
  PointWeights w;
  w.count = 1;
  w.node[0] = 0;
  w.weight[0] = 1.0;
  ContactCompliance cc;
  Mat3 c = Mat3::Constant(7.0);
  // nothing holds it: no compliance exists (not "rigid", C = 0, nor round-off garbage), and c is untouched
  EXPECT_FALSE(cc.compute(lat, w, true, &c));
  EXPECT_EQ(c, Mat3::Constant(7.0));
  // held again: the same solver answers
  EXPECT_TRUE(cc.compute(star(50.0), w, true, &c));
  EXPECT_LT((c - Mat3::Identity() / 100.0).norm(), 1e-12);
}

TEST(ContactCompliance, PieceCutFreeOfItsFixedNodesIsReported) {
  // the star plus a pair of nodes joined only to each other (a piece cut free): singular, whatever the point
  Lattice lat = star(50.0);
  lat.rest_m.push_back(Vec3(3, 0, 0));
  lat.rest_m.push_back(Vec3(4, 0, 0));
  lat.x_m = lat.rest_m;
  lat.v_m_per_s.assign(9, Vec3::Zero());
  lat.mass_kg.assign(9, 1.0);
  lat.fixed.push_back(0);
  lat.fixed.push_back(0);
  Spring s;
  s.a = 7;
  s.b = 8;
  s.rest_m = 1.0;
  s.k_N_per_m = 50.0;
  lat.springs.push_back(s);
  expect_no_compliance_at_the_centre(lat);
}

TEST(ContactCompliance, TiltedPieceCutFreeIsReported) {
  // the star plus a tetrahedron of springs joined to nothing else, tilted off the axes: its rigid motions leave
  // pivots at round-off level rather than exactly zero, and those must be recognised too
  Lattice lat = star(50.0);
  const Vec3 corners[4] = {Vec3(3.1, 0.2, 0.3), Vec3(4.05, 0.47, 0.11), Vec3(3.4, 1.13, 0.52), Vec3(3.52, 0.41, 1.27)};
  for (const Vec3& p : corners) {
    lat.rest_m.push_back(p);
    lat.fixed.push_back(0);
  }
  lat.x_m = lat.rest_m;
  lat.v_m_per_s.assign(lat.rest_m.size(), Vec3::Zero());
  lat.mass_kg.assign(lat.rest_m.size(), 1.0);
  for (int32_t a = 7; a < 11; ++a)
    for (int32_t b = a + 1; b < 11; ++b) {
      Spring s;
      s.a = a;
      s.b = b;
      s.rest_m = (lat.rest_m[static_cast<std::size_t>(b)] - lat.rest_m[static_cast<std::size_t>(a)]).norm();
      s.k_N_per_m = 50.0;
      lat.springs.push_back(s);
    }
  expect_no_compliance_at_the_centre(lat);
}

// C = W^T K^-1 W straight from its definition: K assembled densely over the free dofs (k u u^T per spring) and
// solved by a dense pivoted LU.
Mat3 dense_compliance(const Lattice& lat, const PointWeights& w) {
  std::vector<int> dof(lat.num_nodes(), -1);
  int nd = 0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (!lat.fixed[i]) dof[i] = 3 * nd++;
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(3 * nd, 3 * nd);
  for (const Spring& s : lat.springs) {
    const Vec3 u = (lat.x_m[s.b] - lat.x_m[s.a]).normalized();
    const Mat3 ks = s.k_N_per_m * u * u.transpose();
    const int a = dof[static_cast<std::size_t>(s.a)], b = dof[static_cast<std::size_t>(s.b)];
    if (a >= 0) k.block<3, 3>(a, a) += ks;
    if (b >= 0) k.block<3, 3>(b, b) += ks;
    if (a >= 0 && b >= 0) {
      k.block<3, 3>(a, b) -= ks;
      k.block<3, 3>(b, a) -= ks;
    }
  }
  Eigen::MatrixXd wm = Eigen::MatrixXd::Zero(3 * nd, 3);
  for (int i = 0; i < w.count; ++i)
    if (const int d = dof[static_cast<std::size_t>(w.node[i])]; d >= 0) wm.block<3, 3>(d, 0) += w.weight[i] * Mat3::Identity();
  return wm.transpose() * k.fullPivLu().solve(wm);
}

TEST(ContactCompliance, DeformedBlockLatticeMatchesADenseSolve) {
  // a 4^3-cell block of a level-4 grid, its border fixed, every node moved at random (springs off their axes, so
  // K's blocks are full 3x3): C agrees with the dense solve to round-off, for points here and there, and again
  // after the lattice moves on (refactor) with the same solver
  LatticeSpec spec = test::spec_for(4, 40, 20, 10);
  Lattice lat = test::make_block(4, 4, spec);
  int free_nodes = 0;
  for (uint8_t f : lat.fixed) free_nodes += f ? 0 : 1;
  ASSERT_GT(free_nodes, 20);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  ContactCompliance cc;
  for (int round = 0; round < 2; ++round) {
    for (std::size_t i = 0; i < lat.num_nodes(); ++i)
      lat.x_m[i] = lat.rest_m[i] + lat.cell_m * Vec3(jitter(rng), jitter(rng), jitter(rng));
    for (int point = 0; point < 4; ++point) {
      // a triangle corner's worth of cell nodes, free and fixed, with weights summing to 1
      PointWeights w;
      std::uniform_int_distribution<int32_t> node(0, static_cast<int32_t>(lat.num_nodes()) - 1);
      double sum = 0.0;
      for (int i = 0; i < 12; ++i) {
        const double wi = 0.1 + std::abs(jitter(rng));
        ASSERT_TRUE(w.add(node(rng), wi));
        sum += wi;
      }
      for (int i = 0; i < w.count; ++i) w.weight[i] /= sum;
      Mat3 c;
      ASSERT_TRUE(cc.compute(lat, w, point == 0, &c));
      const Mat3 ref = dense_compliance(lat, w);
      ASSERT_GT(ref.norm(), 0.0);
      EXPECT_LT((c - ref).norm(), 1e-10 * ref.norm()) << "round " << round << " point " << point << "\n" << c << "\n" << ref;
    }
  }
}

TEST(ContactCompliance, AnotherLatticeOfTheSameSizeIsFactoredAnew) {
  // a region moved by a cell has as many nodes and springs as before: the lattice's revision says it is new
  LatticeSpec spec = test::spec_for(4, 40, 20, 10);
  const Lattice a = test::make_block(4, 3, spec);
  Lattice b = a;
  for (std::size_t i = 0; i < b.num_nodes(); ++i) b.x_m[i] += 0.2 * b.cell_m * Vec3(std::sin(3.0 * i), std::cos(5.0 * i), 0.5);
  b.touch();
  PointWeights w;
  for (int32_t i = 0; i < static_cast<int32_t>(a.num_nodes()); i += 7) ASSERT_TRUE(w.add(i, 1.0));
  for (int i = 0; i < w.count; ++i) w.weight[i] = 1.0 / w.count;
  ContactCompliance cc;
  Mat3 c;
  ASSERT_TRUE(cc.compute(a, w, true, &c));
  const Mat3 ref_a = dense_compliance(a, w), ref_b = dense_compliance(b, w);
  EXPECT_LT((c - ref_a).norm(), 1e-10 * ref_a.norm());
  ASSERT_GT((ref_b - ref_a).norm(), 1e-3 * ref_a.norm());
  ASSERT_TRUE(cc.compute(b, w, false, &c));
  EXPECT_LT((c - ref_b).norm(), 1e-10 * ref_b.norm());
}

TEST(ContactCompliance, AFactorisationSpreadOverCallsGivesTheSameCompliance) {
  // 343 free nodes (more than 256): with a work budget the factorisation takes one call for each of assembly,
  // ordering and analysis and then slices of columns, and ends with exactly the compliance of one call
  LatticeSpec spec = test::spec_for(5, 40, 20, 10);
  Lattice a = test::make_block(5, 8, spec);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2);
  for (std::size_t i = 0; i < a.num_nodes(); ++i) a.x_m[i] = a.rest_m[i] + a.cell_m * Vec3(jitter(rng), jitter(rng), jitter(rng));
  Lattice b = a;
  for (std::size_t i = 0; i < b.num_nodes(); ++i) b.x_m[i] += 0.1 * b.cell_m * Vec3(jitter(rng), jitter(rng), jitter(rng));
  b.touch();
  PointWeights w;
  for (int32_t i = 0; i < static_cast<int32_t>(a.num_nodes()); i += 31) ASSERT_TRUE(w.add(i, 1.0));
  for (int i = 0; i < w.count; ++i) w.weight[i] = 1.0 / w.count;
  Mat3 whole_a, whole_b;
  ContactCompliance one;
  ASSERT_TRUE(one.compute(a, w, true, &whole_a));
  ASSERT_TRUE(one.compute(b, w, false, &whole_b));

  ContactCompliance sliced;
  sliced.set_work_per_call(2000);
  sliced.reserve(static_cast<int64_t>(a.num_nodes()), static_cast<int64_t>(a.springs.size()), false);
  Mat3 c = Mat3::Constant(7.0);
  int calls = 1;
  for (; !sliced.compute(a, w, false, &c); ++calls) {
    ASSERT_TRUE(sliced.factoring());
    ASSERT_EQ(c, Mat3::Constant(7.0));  // untouched until done
    ASSERT_LT(calls, 10000);
  }
  EXPECT_FALSE(sliced.factoring());
  EXPECT_GT(calls, 4);
  EXPECT_EQ(c, whole_a);
  // a lattice that changes midway starts again, and ends with its own compliance
  ASSERT_FALSE(sliced.compute(a, w, true, &c));
  ASSERT_FALSE(sliced.compute(a, w, false, &c));
  while (!sliced.compute(b, w, false, &c)) ASSERT_TRUE(sliced.factoring());
  EXPECT_EQ(c, whole_b);
  // a region of 8 free nodes is small: factored in the first call, budget or not
  const Lattice small = test::make_block(4, 3, test::spec_for(4, 40, 20, 10));
  PointWeights ws;
  ws.count = 1;
  ws.node[0] = 0;
  ws.weight[0] = 1.0;
  EXPECT_TRUE(sliced.compute(small, ws, true, &c));
}

}  // namespace
}  // namespace palpate
