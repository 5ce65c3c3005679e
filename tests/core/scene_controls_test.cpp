// The controls a person may change while a run goes on (core/scene_controls.h): the scene each state makes, the modes
// a scene can switch to, the ranges its keys state, and what is refused and why.
#include <gtest/gtest.h>

#include <string>

#include "core/scene.h"
#include "core/scene_controls.h"

namespace palpate {
namespace {

Scene scene_of(const std::string& text) {
  auto s = parse_scene(text, "controls.json");
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
  return s.ok() ? s.value() : Scene{};
}

std::string refusal(const std::string& text) {
  auto s = parse_scene(text, "controls.json");
  return s.ok() ? std::string() : s.error().message;
}

// a touch scene with a sphere tool on a volumetric material, and a pull scene on raw springs
const char* kSphereTouch = R"({"mesh": {"box_m": [0.05, 0.05, 0.05]}, "interaction": {"mode": "touch"},
  "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}],
  "material": {"young_modulus_Pa": 3e4, "poisson_ratio": 0.45, "density_kg_per_m3": 1000, "model": "volumetric"},
  "lattice": {"integrator": "implicit_euler"},
  "device": {"tool_shape": "sphere", "tool_radius_m": 0.002, "contact": "solved"}})";
const char* kSpringPull = R"({"mesh": {"box_m": [0.05, 0.05, 0.05]}, "interaction": {"mode": "pull"},
  "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}],
  "lattice": {"stiffness_N_per_m": {"structural": 40, "shear": 20, "bend": 10}},
  "device": {"tool_radius_m": 0.003, "browser_stiffness_range": [0.5, 2], "browser_tool_radius_range_m": [0.001, 0.005]}})";

TEST(SceneControls, EachStateMakesItsSceneTheToolsShapeKeptOnlyInTouch) {
  const Scene touch = scene_of(kSphereTouch);
  const Controls own = scene_controls(touch);
  EXPECT_EQ(own.seq, 0);
  EXPECT_EQ(own.mode, InteractionMode::kTouch);
  EXPECT_EQ(own.stiffness_scale, 1.0);
  EXPECT_EQ(own.tool_radius_m, 0.002);

  Controls c = own;
  c.stiffness_scale = 2.5;
  c.tool_radius_m = 0.004;
  Scene s = scene_with_controls(touch, c);
  EXPECT_DOUBLE_EQ(s.lattice.material.young_modulus_Pa, 7.5e4);
  EXPECT_EQ(s.lattice.material.poisson_ratio, 0.45);
  EXPECT_EQ(s.device.tool_radius_m, 0.004);
  EXPECT_TRUE(s.device.sphere_tool);
  EXPECT_TRUE(s.device.solved_contact);
  EXPECT_EQ(scene_conflict(s), "");

  // pull: a point (the sphere and the solved contact are a touch's); back in touch, the scene's sphere again
  c.mode = InteractionMode::kPull;
  s = scene_with_controls(touch, c);
  EXPECT_EQ(s.mode, InteractionMode::kPull);
  EXPECT_FALSE(s.device.sphere_tool);
  EXPECT_FALSE(s.device.solved_contact);
  EXPECT_EQ(scene_conflict(s), "");
  c.mode = InteractionMode::kTouch;
  EXPECT_TRUE(scene_with_controls(touch, c).device.sphere_tool);

  // a raw lattice: its springs scale, its masses and damping do not
  const Scene pull = scene_of(kSpringPull);
  Controls k = scene_controls(pull);
  k.stiffness_scale = 2.0;
  s = scene_with_controls(pull, k);
  EXPECT_EQ(s.lattice.structural_N_per_m, 80.0);
  EXPECT_EQ(s.lattice.shear_N_per_m, 40.0);
  EXPECT_EQ(s.lattice.bend_N_per_m, 20.0);
  EXPECT_EQ(s.lattice.node_mass_kg, pull.lattice.node_mass_kg);
  EXPECT_EQ(s.lattice.damping_Ns_per_m, pull.lattice.damping_Ns_per_m);
}

TEST(SceneControls, AModeIsOfferedOnlyWhenItsSceneHasNoConflict) {
  // the volumetric material cannot be cut (its cells' term would hold the cut together): touch and pull only
  const ControlLimits touch = control_limits(scene_of(kSphereTouch));
  ASSERT_EQ(touch.modes.size(), 2u);
  EXPECT_EQ(touch.modes[0], InteractionMode::kTouch);
  EXPECT_EQ(touch.modes[1], InteractionMode::kPull);
  EXPECT_TRUE(touch.material);
  EXPECT_EQ(touch.young_modulus_Pa, 3e4);
  // the default ranges: a quarter to four times the stiffness, half to twice the radius
  EXPECT_EQ(touch.stiffness_lo, 0.25);
  EXPECT_EQ(touch.stiffness_hi, 4.0);
  EXPECT_DOUBLE_EQ(touch.radius_lo_m, 0.001);
  EXPECT_DOUBLE_EQ(touch.radius_hi_m, 0.004);
  Controls cut = scene_controls(scene_of(kSphereTouch));
  cut.mode = InteractionMode::kCut;
  const std::string why = refuse_controls(scene_of(kSphereTouch), cut);
  EXPECT_NE(why.find("mode 'cut' is not one this scene can switch to"), std::string::npos) << why;
  EXPECT_NE(why.find("material.model: 'volumetric' is not supported with interaction.mode 'cut'"), std::string::npos) << why;

  // springs: every mode, its own first; the ranges its keys give
  const ControlLimits pull = control_limits(scene_of(kSpringPull));
  ASSERT_EQ(pull.modes.size(), 3u);
  EXPECT_EQ(pull.modes[0], InteractionMode::kPull);
  EXPECT_FALSE(pull.material);
  EXPECT_EQ(pull.stiffness_lo, 0.5);
  EXPECT_EQ(pull.stiffness_hi, 2.0);
  EXPECT_EQ(pull.radius_lo_m, 0.001);
  EXPECT_EQ(pull.radius_hi_m, 0.005);
}

TEST(SceneControls, ValuesOutsideTheScenesRangesAreRefusedNamingTheKey) {
  const Scene pull = scene_of(kSpringPull);
  Controls c = scene_controls(pull);
  EXPECT_EQ(refuse_controls(pull, c), "");
  c.stiffness_scale = 2.0;
  c.tool_radius_m = 0.005;
  c.mode = InteractionMode::kCut;
  EXPECT_EQ(refuse_controls(pull, c), "");
  c.stiffness_scale = 2.5;
  EXPECT_EQ(refuse_controls(pull, c),
            "stiffness 2.5 is outside the scene's range [0.5, 2] (device.browser_stiffness_range)");
  c.stiffness_scale = 0.4;
  EXPECT_NE(refuse_controls(pull, c).find("stiffness 0.4 is outside"), std::string::npos);
  c.stiffness_scale = 1.0;
  c.tool_radius_m = 0.0051;
  EXPECT_EQ(refuse_controls(pull, c),
            "tool radius 5.1 mm is outside the scene's range [1, 5] mm (device.browser_tool_radius_range_m)");
}

TEST(SceneControls, TheRangeKeysAreCheckedWhereTheSceneIsRead) {
  const std::string head =
      R"({"mesh": {"box_m": [0.05, 0.05, 0.05]}, "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}],
          "device": {"tool_radius_m": 0.003, )";
  EXPECT_EQ(refusal(head + R"("browser_stiffness_range": [2, 4]}})"),
            "scene 'controls.json': device.browser_stiffness_range: [2, 4] must hold 1 (the scene's own stiffness, "
            "where a run starts)");
  EXPECT_EQ(refusal(head + R"("browser_stiffness_range": [4, 0.5]}})"),
            "scene 'controls.json': device.browser_stiffness_range: low 4 is above high 0.5");
  EXPECT_EQ(refusal(head + R"("browser_stiffness_range": [0.5]}})"),
            "scene 'controls.json': device.browser_stiffness_range: must be an array of 2 numbers [low, high]");
  EXPECT_EQ(refusal(head + R"("browser_stiffness_range": [0, 2]}})"),
            "scene 'controls.json': device.browser_stiffness_range: 0 out of range [0.001, 1000]");
  EXPECT_EQ(refusal(head + R"("browser_tool_radius_range_m": [0.004, 0.006]}})"),
            "scene 'controls.json': device.browser_tool_radius_range_m: [0.004, 0.006] must hold device.tool_radius_m "
            "0.003 (where a run starts)");
  EXPECT_EQ(refusal(head + R"("browser_stiffness_range": [1, 1], "browser_tool_radius_range_m": [0.003, 0.003]}})"), "");
}

}  // namespace
}  // namespace palpate
