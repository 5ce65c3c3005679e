// A point tool pressed into a soft block whose region is too large to factor in one frame: until its compliance is
// factored (in slices, over many frames) the servo takes a compliance estimated from the lattice's stiffness, so it
// does not overshoot past a surface far softer than its coupling each frame. The force comes to rest, steady from
// tick to tick, with no release.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/scene.h"
#include "tools/session/model.h"
#include "tools/session/tool_hold.h"

namespace palpate {
namespace {

// a 6 cm cube of 10 kPa (cube_press's softened), lattice level 5 (3.75 mm cells) over 2.25 cm: 1568 nodes, factored
// in slices; the 2 mm point tool held 8 mm under the top face
constexpr const char* kSoftCube = R"({
  "mesh": {"box_m": [0.06, 0.06, 0.06], "box_subdivisions": 12, "size_m": 0.06},
  "grid": {"levels": 5},
  "lattice": {"level": 5, "radius_cells": 6, "fix_floor": true, "integrator": "local_global", "iterations": 3,
              "gravity_m_per_s2": [0, 0, 0]},
  "material": {"young_modulus_Pa": 1e4, "poisson_ratio": 0.25, "density_kg_per_m3": 1070, "stiffness_damping_s": 2e-4},
  "device": {"max_force_N": 3.3, "coupling_N_per_m": 300, "coupling_damping_Ns_per_m": 0.5, "tool_radius_m": 0.002,
             "workspace_half_m": 0.2},
  "interaction": {"mode": "touch"},
  "trajectory": [{"t_s": 0.0, "pos_m": [0.004, 0.004, 0.045]}]
})";

TEST(SoftPress, APointToolOnASurfaceSofterThanItsCouplingComesToRestWithoutChatter) {
  const Scene scene = parse_scene(kSoftCube, "soft_cube.json").value();
  const Model model = load_model(scene).value();
  ToolHoldOptions o;
  o.device_pos_m = Vec3(0.004, 0.004, 0.022);
  o.start_pos_m = Vec3(0.004, 0.004, 0.045);
  o.approach_s = 0.2;
  o.max_s = 3.0;
  o.record_ticks = true;
  const auto r = hold_tool(scene, model, o);
  ASSERT_TRUE(r) << r.error().message;
  const ToolHoldResult& h = r.value();
  ASSERT_GT(h.nodes, 1000u);  // more than one frame's factor: the slices are what is tested
  EXPECT_TRUE(h.at_rest) << h.frames << " frames, node speed " << h.max_node_speed_m_per_s;
  // from 0.1 s after the approach to the end: never released, and no tick steps the force by more than 0.02 N
  const std::size_t from = 300;
  ASSERT_GT(h.tick_force_N.size(), from + 100);
  double least = 1e9, step = 0.0;
  for (std::size_t i = from; i < h.tick_force_N.size(); ++i) {
    least = std::min(least, h.tick_force_N[i].z());
    step = std::max(step, (h.tick_force_N[i] - h.tick_force_N[i - 1]).norm());
  }
  EXPECT_GT(least, 0.1) << "released (or pulled) after the approach";
  EXPECT_LT(step, 0.02) << "at rest after " << h.frames << " frames";
}

}  // namespace
}  // namespace palpate
