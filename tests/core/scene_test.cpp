#include "core/scene.h"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
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

// Every enum the scene spells as text: each name reads back as its value, names are distinct, and an unknown name
// is an error that lists the table.
template <typename E>
void expect_round_trip() {
  const auto table = names(E{});
  for (const auto& [value, name] : table.entries) {
    EXPECT_EQ(from_name<E>(name), value) << name;
    EXPECT_STREQ(name_of(value), name);
    int same = 0;
    for (const auto& other : table.entries) same += std::string(other.second) == name;
    EXPECT_EQ(same, 1) << name;
  }
  EXPECT_FALSE(from_name<E>("no-such-name").has_value());
}

TEST(SceneEnums, EveryNameReadsBackAsItsValue) {
  expect_round_trip<IntegratorKind>();
  expect_round_trip<InteractionMode>();
  expect_round_trip<RunMode>();
  expect_round_trip<RenderStyle>();
  expect_round_trip<RenderBackend>();
  expect_round_trip<DeviceDriver>();
}

TEST(SceneEnums, SceneKeysBecomeEnumsOrNameTheChoices) {
  const std::string traj = R"("trajectory": [{"t_s": 0, "pos_m": [0,0,0.05]}])";
  const std::string box = R"("mesh": {"box_m": [0.05,0.05,0.05]}, )";
  auto r = parse_scene("{" + box + R"("render": {"style": "both", "backend": "egl"}, "device": {"driver": "replay", "link": "x"},
      "interaction": {"mode": "cut"}, "run_mode": "realtime", )" + traj + "}", "s.json");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().render.style, RenderStyle::kBoth);
  EXPECT_EQ(r.value().render.backend, RenderBackend::kEgl);
  EXPECT_EQ(r.value().render.wire_min_edge_px, kWireMinEdgePxDefault);
  EXPECT_EQ(r.value().render.lod_min_edge_px, kLodMinEdgePxDefault);
  EXPECT_EQ(r.value().device.driver, DeviceDriver::kReplay);
  EXPECT_EQ(r.value().mode, InteractionMode::kCut);
  EXPECT_EQ(r.value().run_mode, RunMode::kRealtime);
  expect_error("{" + box + R"("render": {"style": "shaded"}, )" + traj + "}",
               "render.style: 'shaded' is not one of: solid, wireframe, both");
  expect_error("{" + box + R"("render": {"backend": "vulkan"}, )" + traj + "}",
               "render.backend: 'vulkan' is not one of: auto, osmesa, egl");
  expect_error("{" + box + R"("device": {"driver": "usb"}, )" + traj + "}",
               "device.driver: 'usb' is not one of: scripted, shm, plugin, replay, browser");
  expect_error("{" + box + R"("interaction": {"mode": "poke"}, )" + traj + "}",
               "interaction.mode: 'poke' is not one of: touch, pull, cut");
  expect_error("{" + box + R"("run_mode": "fast", )" + traj + "}", "run_mode: 'fast' is not one of: lockstep, realtime");
}

TEST(Scene, MinimalSceneTakesDefaults) {
  auto r = parse_scene(kMinimal, "dir/s.json");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().name, "s");
  EXPECT_EQ(r.value().lattice.integrator, IntegratorKind::kSymplecticEuler);
  EXPECT_EQ(r.value().trajectory.size(), 1u);
}

TEST(Scene, ShippedScenesParse) {
  for (const char* name : {"scenes/bunny_touch.json", "scenes/bunny_pull.json", "scenes/bunny_pull_explicit.json",
                           "scenes/bunny_cut.json", "scenes/cube_press.json", "scenes/phantom_press.json",
                           "scenes/tissue_pull.json", "scenes/block_stroke.json"}) {
    auto r = load_scene(test::source_path(name));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_FALSE(r.value().trajectory.empty());
  }
}

TEST(Scene, FrictionAndJumpLimitKeys) {
  auto plain = parse_scene(kMinimal, "s.json");
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ(plain.value().static_friction, 0.0);  // frictionless unless asked
  EXPECT_EQ(plain.value().dynamic_friction, 0.0);
  EXPECT_TRUE(plain.value().warnings.empty());
  EXPECT_EQ(plain.value().device.jump_limit_N_per_tick, 0.02);
  // friction is the surface material's: an object of friction alone leaves the lattice to its raw keys
  auto f = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "device": {"jump_limit_N_per_tick": 0.05},
                           "material": {"static_friction": 0.5, "dynamic_friction": 0.3},
                           "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f.value().static_friction, 0.5);
  EXPECT_EQ(f.value().dynamic_friction, 0.3);
  EXPECT_FALSE(f.value().lattice.material.enabled);
  EXPECT_TRUE(f.value().warnings.empty());
  EXPECT_EQ(f.value().device.jump_limit_N_per_tick, 0.05);
  // beside the mechanical keys, which a material object then needs in full
  auto full = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "material": {"young_modulus_Pa": 3e5, "poisson_ratio": 0.45,
                              "density_kg_per_m3": 1070, "static_friction": 0.6, "dynamic_friction": 0.4},
                              "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(full) << full.error().message;
  EXPECT_TRUE(full.value().lattice.material.enabled);
  EXPECT_EQ(full.value().static_friction, 0.6);
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "material": {"young_modulus_Pa": 3e5, "static_friction": 0.6},
                   "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "material.poisson_ratio");
  // the old place is read, with a warning that names both places
  auto old = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "interaction": {"static_friction": 0.5, "dynamic_friction": 0.3},
                             "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(old) << old.error().message;
  EXPECT_EQ(old.value().static_friction, 0.5);
  EXPECT_EQ(old.value().dynamic_friction, 0.3);
  ASSERT_EQ(old.value().warnings.size(), 2u);
  EXPECT_NE(old.value().warnings[0].find("interaction.static_friction is read as material.static_friction"),
            std::string::npos) << old.value().warnings[0];
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "material": {"static_friction": 0.5},
                   "interaction": {"static_friction": 0.5}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "interaction.static_friction: given twice, here and as material.static_friction");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "material": {"static_friction": 0.2, "dynamic_friction": 0.3},
                   "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "material.dynamic_friction 0.3 exceeds material.static_friction 0.2");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "interaction": {"static_friction": 0.2, "dynamic_friction": 0.3},
                   "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "material.dynamic_friction 0.3 exceeds material.static_friction 0.2");
  // mesh.subdivisions: "auto" (the default) or a number, nothing else
  EXPECT_EQ(plain.value().mesh.subdivisions, kAutoSubdivisions);
  expect_error(R"({"mesh": {"file": "m.obj", "subdivisions": "many"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "mesh.subdivisions: 'many' must be \"auto\" or 0..7");
  expect_error(R"({"mesh": {"file": "m.obj", "subdivisions": 8}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "mesh.subdivisions");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "device": {"jump_limit_N_per_tick": -1},
                   "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "device.jump_limit_N_per_tick");
}

TEST(Scene, ForceShadingIsOffUnlessAskedAndACreaseAngle) {
  auto plain = parse_scene(kMinimal, "s.json");
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ(plain.value().device.force_shading_deg, 0.0);
  auto on = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "device": {"force_shading_deg": 60},
                            "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(on) << on.error().message;
  EXPECT_EQ(on.value().device.force_shading_deg, 60.0);
  for (const char* bad : {"-1", "181", "\"yes\""})
    expect_error(std::string(R"({"mesh": {"box_m": [1,1,1]}, "device": {"force_shading_deg": )") + bad +
                     R"(}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
                 "device.force_shading_deg");
}

TEST(Scene, RefineIsOffUnlessAskedAndNamesWhatItNeeds) {
  auto plain = parse_scene(kMinimal, "s.json");
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_EQ(plain.value().lattice.refine.level, 0);
  auto scene = [](const std::string& lattice, const std::string& material) {
    return R"({"mesh": {"box_m": [1,1,1]}, "grid": {"levels": 7}, "lattice": {"level": 4, )" + lattice + "}" + material +
           R"(, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})";
  };
  const std::string springs = R"(, "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.25, "density_kg_per_m3": 1000})";
  auto ok = parse_scene(scene(R"("integrator": "implicit_euler", "refine": {"level": 6, "radius_m": 0.01})", springs), "s.json");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok.value().lattice.refine.level, 6);
  EXPECT_EQ(ok.value().lattice.refine.radius_m, 0.01);
  // each cell's volume or Neo-Hookean term takes its own edge: any material.model refines
  for (const char* model : {"volumetric", "neo_hookean"}) {
    auto cells = parse_scene(scene(R"("integrator": "implicit_euler", "refine": {"level": 6, "radius_m": 0.01})",
                                   R"(, "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.45, "density_kg_per_m3": 1000, "model": ")" +
                                       std::string(model) + "\"}"),
                             "s.json");
    ASSERT_TRUE(cells) << model << ": " << cells.error().message;
  }
  expect_error(scene(R"("integrator": "implicit_euler", "refine": {"level": 4, "radius_m": 0.01})", springs),
               "lattice.refine.level 4 is not finer than lattice.level 4");
  expect_error(scene(R"("integrator": "implicit_euler", "refine": {"level": 8, "radius_m": 0.01})", springs),
               "more than 3 levels finer");
  expect_error(scene(R"("integrator": "local_global", "refine": {"level": 6, "radius_m": 0.01})", springs),
               "lattice.refine needs lattice.integrator 'implicit_euler'");
  expect_error(scene(R"("integrator": "implicit_euler", "refine": {"level": 6, "radius_m": 0.01})", ""),
               "lattice.refine needs a \"material\"");
  expect_error(scene(R"("integrator": "implicit_euler", "refine": {"level": 6})", springs), "lattice.refine.radius_m");
}

TEST(Scene, ToolShapeIsAPointUnlessASphereIsAskedForATouch) {
  auto point = parse_scene(kMinimal, "s.json");
  ASSERT_TRUE(point) << point.error().message;
  EXPECT_FALSE(point.value().device.sphere_tool);
  auto sphere = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "device": {"tool_shape": "sphere", "tool_radius_m": 0.005},
                                "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(sphere) << sphere.error().message;
  EXPECT_TRUE(sphere.value().device.sphere_tool);
  EXPECT_EQ(sphere.value().device.tool_radius_m, 0.005);
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "device": {"tool_shape": "cube"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "device.tool_shape: 'cube' is not one of: point, sphere");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "device": {"tool_shape": "sphere"}, "interaction": {"mode": "pull"},
                   "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "device.tool_shape: 'sphere' is a touch tool; interaction.mode is 'pull'");
}

TEST(Scene, TheContactIsPrescribedUnlessSolvedIsAskedForATouch) {
  auto prescribed = parse_scene(kMinimal, "s.json");
  ASSERT_TRUE(prescribed) << prescribed.error().message;
  EXPECT_FALSE(prescribed.value().device.solved_contact);
  auto solved = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "device": {"contact": "solved"},
                                "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(solved) << solved.error().message;
  EXPECT_TRUE(solved.value().device.solved_contact);
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "device": {"contact": "hertz"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "device.contact: 'hertz' is not one of: prescribed, solved");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "device": {"contact": "solved"}, "interaction": {"mode": "cut"},
                   "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "device.contact: 'solved' is for a touch; interaction.mode is 'cut'");
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
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"wire_min_edge_px": -1}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.wire_min_edge_px: -1 out of range");
  auto wire = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "render": {"wire_min_edge_px": 0}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(wire) << wire.error().message;
  EXPECT_EQ(wire.value().render.wire_min_edge_px, 0.0);
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"lod_min_edge_px": 101}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.lod_min_edge_px: 101 out of range");
  // what a frame shows besides the model: the colours, their range, the arrow, the legend, the floor, the samples
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"color": "red"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.color: 'red' is not one of");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"color_range_m": -0.01}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.color_range_m: -0.01 out of range");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"force_arrow": 1}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.force_arrow: must be true or false");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"antialias": 3}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.antialias: 3 samples a pixel: give \"edges\" (the default), \"none\" (or 0), 2, 4 or 8");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"antialias": "smooth"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.antialias: 'smooth' is not one of: edges, none");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"antialias": 16}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.antialias: 16 out of range");
  auto look = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "render": {"color": "none", "color_range_m": 0.004, "force_arrow": false, "legend": false, "floor": false, "antialias": 4}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(look) << look.error().message;
  EXPECT_EQ(look.value().render.color, RenderColor::kNone);
  EXPECT_EQ(look.value().render.color_range_m, 0.004);
  EXPECT_FALSE(look.value().render.force_arrow || look.value().render.legend || look.value().render.floor);
  EXPECT_EQ(look.value().render.antialias, 4);
  for (const char* a : {"\"edges\"", "\"none\""}) {
    auto named = parse_scene(std::string(R"({"mesh": {"box_m": [1,1,1]}, "render": {"antialias": )") + a +
                                 R"(}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
    ASSERT_TRUE(named) << named.error().message;
    EXPECT_EQ(named.value().render.antialias, a[1] == 'e' ? kAntialiasEdges : 0);
  }
  EXPECT_EQ(Scene{}.render.antialias, kAntialiasEdges);  // smoothed edges unless asked otherwise
  // the browser device's timing: its watchdog must allow three of the page's sends
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "device": {"browser_send_ms": 40, "browser_stall_ms": 100}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "device.browser_stall_ms: 100 ms is less than three of the page's sends");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "device": {"browser_send_ms": 1}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "device.browser_send_ms: 1 out of range");
  auto timing = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "device": {"browser_send_ms": 30, "browser_stall_ms": 800}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(timing) << timing.error().message;
  EXPECT_EQ(timing.value().device.browser_stall_ms, 800.0);
  EXPECT_EQ(timing.value().device.browser_send_ms, 30.0);
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "interaction": {"mode": "cut"}, "render": {"color": "strain"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.color: 'strain' is not drawn in interaction.mode 'cut'");
  auto strain = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "render": {"color": "strain", "strain_range": 0.05}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(strain) << strain.error().message;
  EXPECT_TRUE(colors_by_strain(strain.value()));
  EXPECT_FALSE(colors_by_displacement(strain.value()));
  EXPECT_EQ(strain.value().render.strain_range, 0.05);
  // auto: displacement colours in touch and pull, none in cut
  Scene cut = look.value();
  cut.render.color = RenderColor::kAuto;
  EXPECT_TRUE(colors_by_displacement(cut));
  cut.mode = InteractionMode::kCut;
  EXPECT_FALSE(colors_by_displacement(cut));

  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"view_from": [0,0,0]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.view_from: must be a direction (not zero)");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"view_from": [0,1]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.view_from");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"look_at_m": [0,0,0]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.look_at_m: needs render.look_at_m and render.frame_radius_m together");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"frame_radius_m": 0}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "render.frame_radius_m: 0 out of range");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "interaction": {"blade_width_m": 0.05}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "interaction.blade_width_m: 0.05 out of range");
  auto view = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "render": {"view_from": [0,0,2]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(view) << view.error().message;
  EXPECT_EQ(view.value().render.view_from, Vec3(0, 0, 2));
  auto lod = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "render": {"lod_min_edge_px": 0}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(lod) << lod.error().message;
  EXPECT_EQ(lod.value().render.lod_min_edge_px, 0.0);
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 1, "pos_m": [0,0,0]}, {"t_s": 0.5, "pos_m": [0,0,0]}]})", "trajectory[1].t_s: 0.5 must be later");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "grid": {"levels": 3}, "lattice": {"level": 4}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "deeper than grid.levels");
}

TEST(Scene, FrameBudgetNeedsLocalGlobal) {
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "lattice": {"budget_ms": 8}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "lattice.budget_ms: needs \"integrator\": \"local_global\"");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "lattice": {"budget_ms": -1, "integrator": "local_global"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "lattice.budget_ms: -1 out of range");
  auto r = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "lattice": {"budget_ms": 8, "integrator": "local_global"}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_DOUBLE_EQ(r.value().lattice.budget_ms, 8.0);
}

TEST(Scene, ServoRateAndDeviceDampingAreSceneKeys) {
  auto r = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "servo": {"rate_hz": 10000}, "device": {"damping_Ns_per_m": 3.5},
                          "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "s.json");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_DOUBLE_EQ(r.value().rates.servo_hz, 10000.0);
  EXPECT_DOUBLE_EQ(r.value().device.damping_Ns_per_m, 3.5);
  EXPECT_DOUBLE_EQ(parse_scene(kMinimal, "s.json").value().rates.servo_hz, 1000.0);
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "servo": {"rate_hz": 50}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "servo.rate_hz: 50 out of range [100, 20000]");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "servo": {"rate": 2000}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "servo.rate: unknown key");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "servo": 2000, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})", "servo: must be an object");
}

TEST(Scene, HostileTextIsRefusedWithAReadableMessage) {
  const std::string mesh = R"("mesh": {"box_m": [0.05, 0.05, 0.05]}, "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}])";
  // 2^63 arrives unsigned: said as itself, not as -9223372036854775808
  EXPECT_EQ(error_of("{" + mesh + R"(, "lattice": {"level": 9223372036854775808}})"),
            "scene 's.json': lattice.level: 9223372036854775808 out of range [1, 8]");
  EXPECT_EQ(error_of("{" + mesh + R"(, "lattice": {"level": 18446744073709551615}})"),
            "scene 's.json': lattice.level: 18446744073709551615 out of range [1, 8]");
  // a NUL byte ends the parser's text: what follows would go unread
  std::string nul = "{" + mesh + "}";
  nul += '\0';
  nul += R"({"lattice": 7})";
  EXPECT_EQ(error_of(nul), "scene 's.json': NUL byte at offset " + std::to_string(mesh.size() + 2) + ": not a JSON text");
  // deep nesting is refused before parsing (its key paths would cost memory quadratic in the depth)
  EXPECT_EQ(error_of("{" + mesh + ", \"x\":\n" + std::string(100000, '[') + std::string(100000, ']') + "}"),
            "scene 's.json': JSON nested deeper than the limit of 64 levels (line 2)");
  // brackets inside strings do not nest
  expect_error("{" + mesh + R"(, "name": "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[\"{"})", "name: '");
  // invalid UTF-8 in the parser's excerpt is escaped
  const std::string e = error_of("{\"name\": \"caf\xff\"}");
  EXPECT_NE(e.find("\\xff"), std::string::npos) << e;
  EXPECT_EQ(e.find('\xff'), std::string::npos) << e;
}

TEST(Scene, AllowDivergenceIsOffUnlessAsked) {
  auto off = parse_scene(kMinimal, "s.json");
  ASSERT_TRUE(off);
  EXPECT_FALSE(off.value().lattice.allow_divergence);
  auto on = parse_scene(R"({"mesh": {"box_m": [0.05, 0.05, 0.05]}, "lattice": {"allow_divergence": true},
      "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}]})", "s.json");
  ASSERT_TRUE(on) << on.error().message;
  EXPECT_TRUE(on.value().lattice.allow_divergence);
  expect_error(R"({"mesh": {"box_m": [0.05, 0.05, 0.05]}, "lattice": {"allow_divergence": 1},
      "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}]})", "lattice.allow_divergence: must be true or false");
}

TEST(Scene, ModelRelativeKeysParseAndAreCheckedNamingTheKey) {
  auto r = parse_scene(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "pos_rel": [0.5, 0.5, 1.2]},
                          {"t_s": 1, "pos_rel": [0.5, 0.5, 0.5], "surface": true, "depth_m": 0.004},
                          {"t_s": 2, "pos_m": [0, 0, 0.1], "surface": true}]})", "s.json");
  ASSERT_TRUE(r) << r.error().message;
  const auto& t = r.value().trajectory;
  ASSERT_TRUE(t[0].pos_rel.has_value());
  EXPECT_TRUE(t[0].pos_rel->isApprox(Vec3(0.5, 0.5, 1.2)));
  EXPECT_FALSE(t[0].surface);
  EXPECT_TRUE(t[1].surface);
  EXPECT_DOUBLE_EQ(t[1].depth_m, 0.004);
  EXPECT_FALSE(t[2].pos_rel.has_value());
  EXPECT_TRUE(needs_model(t[0]) && needs_model(t[1]) && needs_model(t[2]));
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0], "pos_rel": [0,0,0]}]})",
               "trajectory[0].pos_rel: and pos_m are exclusive");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0}]})", "trajectory[0].pos_m: is required");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0], "depth_m": 0.01}]})",
               "trajectory[0].depth_m: needs \"surface\": true");
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "pos_rel": [0,0,11]}]})",
               "trajectory[0].pos_rel[2]: 11 out of range [-10, 10]");
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

// hostile input: every one refused with a message naming the culprit, never an abort or a silent zero

TEST(SceneHostile, NumberTooLargeForADoubleIsAnErrorNamingTheFile) {
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "duration_s": 1e400, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "scene 's.json': invalid JSON");
}

TEST(SceneHostile, DuplicateKeysAreRefused) {
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "lattice": {"level": 2, "level": 3}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "duplicate key 'lattice.level'");
  expect_error(R"({"name": "a", "name": "b", "mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "duplicate key 'name'");
}

TEST(SceneHostile, StringInsideOrientationIsAnError) {
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0], "orientation_wxyz": [1, "x", 0, 0]}]})",
               "trajectory[0].orientation_wxyz: must be an array of 4 finite numbers");
}

TEST(SceneHostile, NameMustBeAPlainFileName) {
  for (const char* name : {"/abs/path", "..", "a/../../b", ".hidden", "a b"})
    expect_error(std::string(R"({"name": ")") + name +
                     R"(", "mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
                 "name: '");
  auto r = parse_scene(kMinimal, "dir/..json");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().name.find('/'), std::string::npos);
  EXPECT_NE(r.value().name.front(), '.');
}

// n keyframes, one a second
std::string keyframes(int n) {
  std::string keys;
  for (int i = 0; i < n; ++i) {
    if (i > 0) keys += ',';
    keys.append(R"({"t_s": )").append(std::to_string(i)).append(R"(, "pos_m": [0,0,0]})");
  }
  return R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [)" + keys + "]}";
}

TEST(SceneHostile, TooManyKeyframesNameTheLimit) {
  EXPECT_EQ(error_of(keyframes(100001)), "scene 's.json': trajectory: 100001 keyframes, more than the limit of 100000");
  // counted to the end while parsing (none past the limit kept): the message gives the file's count
  EXPECT_EQ(error_of(keyframes(250000)), "scene 's.json': trajectory: 250000 keyframes, more than the limit of 100000");
  // the limit itself is accepted, every keyframe read
  auto r = parse_scene(keyframes(100000), "s.json");
  ASSERT_TRUE(r) << r.error().message;
  ASSERT_EQ(r.value().trajectory.size(), 100000u);
  EXPECT_DOUBLE_EQ(r.value().trajectory.back().t_s, 99999.0);
  // only the top-level trajectory counts: a long array elsewhere is an unknown key, not a keyframe flood
  std::string other = R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}], "x": [0)";
  for (int i = 0; i < 100001; ++i) other += ",0";
  EXPECT_EQ(error_of(other + "]}"), "scene 's.json': x: unknown key");
  // a duplicate key inside a keyframe is still found
  EXPECT_EQ(error_of(R"({"mesh": {"box_m": [1,1,1]}, "trajectory": [{"t_s": 0, "t_s": 1, "pos_m": [0,0,0]}]})"),
            "scene 's.json': duplicate key 'trajectory[].t_s'");
}

TEST(SceneHostile, ImageSizeIsLimited) {
  expect_error(R"({"mesh": {"box_m": [1,1,1]}, "render": {"width": 8192, "height": 8192}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})",
               "render: 8192 x 8192 = 67108864 pixels, more than the limit of 16777216");
}

TEST(SceneHostile, DevicesAndFifosAreRefusedWithoutReading) {
  EXPECT_NE(load_scene("/dev/zero").error().message.find("scene '/dev/zero': is not a regular file"), std::string::npos);
  const std::string fifo = test::fresh_dir("scene_fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto r = load_scene(fifo);  // must not block waiting for a writer
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("is not a regular file"), std::string::npos) << r.error().message;
  std::filesystem::remove(fifo);
}

TEST(SceneHostile, HugeFileIsRefusedBeforeReading) {
  const std::string big = test::fresh_dir("scene_big.json");
  {
    std::ofstream f(big, std::ios::binary);
    f << "[";
  }
  std::filesystem::resize_file(big, (int64_t{16} << 20) + 1);  // sparse: no disk used
  auto r = load_scene(big);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("16777217 bytes, more than the limit of 16777216"), std::string::npos)
      << r.error().message;
  std::filesystem::remove(big);
}

}  // namespace
}  // namespace palpate
