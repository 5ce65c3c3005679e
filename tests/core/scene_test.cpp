#include "core/scene.h"

#include <gtest/gtest.h>

#include <fstream>

#include "support/fixtures.h"

namespace palpate {
namespace {

const char* kMinimal = R"({
  "mesh": {"box_m": [0.05, 0.05, 0.05]},
  "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}]
})";

std::string error_of(const std::string& json) {
  auto r = parse_scene(json, "s.json");
  return r ? std::string("(no error)") : r.error().message;
}

void expect_error(const std::string& json, const std::string& needle) {
  const std::string e = error_of(json);
  EXPECT_NE(e.find(needle), std::string::npos) << "got: " << e;
}

TEST(Scene, MinimalSceneTakesDefaults) {
  auto r = parse_scene(kMinimal, "dir/s.json");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().name, "s");
  EXPECT_EQ(r.value().lattice.integrator, IntegratorKind::kSymplecticEuler);
  EXPECT_EQ(r.value().trajectory.size(), 1u);
}

TEST(Scene, ShippedScenesParse) {
  for (const char* name : {"scenes/bunny_touch.json", "scenes/bunny_pull.json", "scenes/cube_press.json"}) {
    auto r = load_scene(test::source_path(name));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_FALSE(r.value().trajectory.empty());
  }
}

TEST(Scene, UnknownKeysAreErrorsNamingTheKey) {
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}], "colour": 1})", "colour: unknown key");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "lattice": {"levle": 3}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "lattice.levle: unknown key");
}

TEST(Scene, OutOfRangeAndWrongTypesNameKeyValueAndLimits) {
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "lattice": {"level": 9}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "lattice.level: 9 out of range [1, 8]");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "lattice": {"node_mass_kg": -1}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "lattice.node_mass_kg: -1 out of range");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "lattice": {"integrator": "verlet"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "lattice.integrator: 'verlet' is not one of");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"width": "big"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.width: must be an integer");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 1, "pos_m": [0,0,0]}, {"t_s": 0.5, "pos_m": [0,0,0]}]})", "trajectory[1].t_s: 0.5 must be later");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "grid": {"levels": 3}, "lattice": {"level": 4}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "deeper than grid.levels");
}

TEST(Scene, MissingPiecesAndBadJson) {
  expect_error(R"({"trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "mesh: is required");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}})", "trajectory: is required");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, )", "scene 's.json': invalid JSON");
  EXPECT_NE(error_of("[1, 2]").find("must be an object"), std::string::npos);
}

TEST(Scene, FileErrorsNameTheFile) {
  EXPECT_NE(load_scene("/nonexistent/x.json").error().message.find("scene '/nonexistent/x.json': file not found"),
            std::string::npos);
  const std::string empty = test::temp_root() + "/empty_scene.json";
  std::ofstream(empty).close();
  EXPECT_NE(load_scene(empty).error().message.find("file is empty"), std::string::npos);
}

}  // namespace
}  // namespace palpate
