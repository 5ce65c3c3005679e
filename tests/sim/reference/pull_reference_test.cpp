// Large-strain references without a closed form: Richardson extrapolation over levels, and the 40 mm pull it checks.

#include <gtest/gtest.h>

#include <cmath>

#include "sim/reference/pull_reference.h"
#include "sim/reference/reference_cases.h"
#include "sim/reference/richardson.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

// f(h) = 2 + 0.5 h^1.5 at h = 1, 1/2, 1/4: the limit 2 and the order 1.5 come back exactly.
TEST(Richardson, RecoversTheLimitAndOrderOfAPowerLaw) {
  auto f = [](double h) { return 2.0 + 0.5 * std::pow(h, 1.5); };
  auto r = richardson_extrapolate(f(1.0), f(0.5), f(0.25));
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_NEAR(r.value().value, 2.0, 1e-12);
  EXPECT_NEAR(r.value().order, 1.5, 1e-12);
}

TEST(Richardson, LevelsThatAgreeAreConvergedAlready) {
  auto r = richardson_extrapolate(3.0, 3.0 + 1e-7, 3.0 - 1e-7);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().value, 3.0 - 1e-7);
  EXPECT_TRUE(std::isnan(r.value().order));
}

TEST(Richardson, RefusesLevelsThatDoNotConvergeMonotonically) {
  auto r = richardson_extrapolate(1.0, 1.2, 1.1);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("not in the asymptotic range"), std::string::npos) << r.error().message;
  EXPECT_FALSE(richardson_extrapolate(1.0, 1.1, 1.3));  // differences growing
}

MaterialSpec tissue() {
  MaterialSpec m = test::soft_material(0.45, MaterialModel::kNeoHookean);
  m.stiffness_damping_s = 0.02;
  return m;
}

// The cube pulled 40 mm (50 % stretch) between glued plates: stiffer than the same cube stretched freely (the closed
// form of uniaxial Neo-Hookean tension, whose sides narrow), and levels 3 and 4 agree within 2 %.
TEST(PullReference, GluedPullIsStifferThanFreeTensionAndConverges) {
  const MaterialSpec m = tissue();
  auto coarse = check_pull(m, 3);
  auto fine = check_pull(m, 4);
  ASSERT_TRUE(coarse) << coarse.error().message;
  ASSERT_TRUE(fine) << fine.error().message;
  const double mu = 1e5 / (2 * 1.45), lambda = 1e5 * 0.45 / (1.45 * 0.1), area_m2 = 0.08 * 0.08;
  const double free_N = neo_hookean_uniaxial_Pa(mu, lambda, 1.5, nullptr) * area_m2;
  EXPECT_GT(fine.value().force_N, free_N);
  EXPECT_LT(fine.value().force_N, 1.5 * free_N);
  EXPECT_NEAR(coarse.value().force_N / fine.value().force_N, 1.0, 0.02);
  EXPECT_EQ(fine.value().handle_nodes, 81u);  // the whole top of a 8 x 8 x 8 cell cube
}

TEST(PullReference, HandleNarrowerThanACellIsAnError) {
  PullGeometry g;
  g.handle_m = 0.01;
  auto r = check_pull(tissue(), 3, g);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("narrower than a cell"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace palpate
