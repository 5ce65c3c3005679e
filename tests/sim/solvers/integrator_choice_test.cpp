// The scene's integrator choice and lattice keys reach the step options; bad values are named errors.
#include <gtest/gtest.h>

#include "core/scene.h"
#include "sim/solvers/integrator.h"

namespace palpate {
namespace {

std::string scene_with(const std::string& lattice) {
  return R"({"mesh": {"box_m": [0.04, 0.04, 0.04]}, "lattice": {)" + lattice +
         R"(}, "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.1]}]})";
}

TEST(IntegratorChoice, EveryNameRoundTripsThroughTheSceneParser) {
  for (auto kind : {IntegratorKind::kExplicitEuler, IntegratorKind::kSymplecticEuler, IntegratorKind::kImplicitEuler,
                    IntegratorKind::kLocalGlobal, IntegratorKind::kRk4}) {
    auto s = parse_scene(scene_with(std::string(R"("integrator": ")") + integrator_name(kind) + "\""), "s.json");
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ(s.value().lattice.integrator, kind);
    IntegratorKind back = IntegratorKind::kRk4;
    EXPECT_TRUE(integrator_from_name(integrator_name(kind), &back));
    EXPECT_EQ(back, kind);
  }
  IntegratorKind k = IntegratorKind::kRk4;
  EXPECT_FALSE(integrator_from_name("verlet", &k));
  EXPECT_EQ(k, IntegratorKind::kRk4);
}

TEST(IntegratorChoice, LatticeKeysReachTheStepOptions) {
  auto s = parse_scene(scene_with(R"("integrator": "local_global", "substeps": 2, "iterations": 7, "strain_limit": 0.3)"),
                       "s.json");
  ASSERT_TRUE(s) << s.error().message;
  const StepOptions o = step_options(s.value().lattice);
  EXPECT_EQ(o.kind, IntegratorKind::kLocalGlobal);
  EXPECT_EQ(o.substeps, 2);
  EXPECT_EQ(o.iterations, 7);
  EXPECT_DOUBLE_EQ(o.strain_limit, 0.3);
}

TEST(IntegratorChoice, UnknownNamesAndOutOfRangeValuesNameTheKey) {
  auto bad = parse_scene(scene_with(R"("integrator": "verlet")"), "s.json");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("lattice.integrator: 'verlet' is not one of: explicit_euler, symplectic_euler, "
                                     "implicit_euler, local_global, rk4"),
            std::string::npos)
      << bad.error().message;
  auto range = parse_scene(scene_with(R"("strain_limit": -0.1)"), "s.json");
  ASSERT_FALSE(range);
  EXPECT_NE(range.error().message.find("lattice.strain_limit: -0.1 out of range [0, 10]"), std::string::npos);
  auto iters = parse_scene(scene_with(R"("iterations": 1.5)"), "s.json");
  ASSERT_FALSE(iters);
  EXPECT_NE(iters.error().message.find("lattice.iterations: must be an integer"), std::string::npos);
  auto typo = parse_scene(scene_with(R"("rest_kinetic": 0.1)"), "s.json");
  ASSERT_FALSE(typo);
  EXPECT_NE(typo.error().message.find("lattice.rest_kinetic: unknown key"), std::string::npos);
}

}  // namespace
}  // namespace palpate
