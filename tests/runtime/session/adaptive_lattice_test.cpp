// The lattice refined where the tool is (lattice.refine): Hertz indentation by the sphere tool within 10 % where the
// coarse uniform lattice it starts from is not, and the fine zone following a stroke without stepping the force.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/scene.h"
#include "tools/bench/bench_model.h"
#include "runtime/session/model.h"
#include "runtime/session/tool_hold.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

MaterialSpec soft_solid() {
  MaterialSpec m = test::soft_material();
  m.stiffness_damping_s = 0.02;
  return m;
}

TEST(AdaptiveLattice, HertzWithinTenPercentWhereTheCoarseUniformLatticeIsNot) {
  const MaterialSpec m = soft_solid();
  auto coarse = check_hertz_tool(m, 4, IntegratorKind::kImplicitEuler);
  RefineSpec refine;
  refine.level = 6;
  refine.radius_m = 0.004;  // 0.8 contact radii (twice that into the body), graded 4 -> 5 -> 6
  auto adaptive = check_hertz_tool(m, 4, IntegratorKind::kImplicitEuler, refine);
  ASSERT_TRUE(coarse) << coarse.error().message;
  ASSERT_TRUE(adaptive) << adaptive.error().message;
  const HertzToolCheck& c = coarse.value();
  const HertzToolCheck& a = adaptive.value();
  EXPECT_GT(std::abs(c.rel_error), 0.10) << c.rel_error;
  EXPECT_LT(std::abs(a.rel_error), 0.10) << "F " << a.force_N << " N, Hertz " << a.closed_form_N << " N";
  EXPECT_NEAR(a.depth_m, 2.5e-4, 1e-4);
  // the fine zone is what carries the patch: many more nodes under it than the coarse cells give
  EXPECT_GT(a.force_nodes, 2 * c.force_nodes);
  // what keeps it near the coarse level's cost (docs/refinement.md): a zone of 1 cm fine cells' worth, 4 -> 5 -> 6
  // (601 nodes against 405; the one-jump zone within 1 cm had 1107) and a conjugate gradient solve not much longer
  // (31 iterations a frame against 24; the one-jump zone took 37)
  EXPECT_LT(static_cast<double>(a.nodes), 1.6 * static_cast<double>(c.nodes)) << a.nodes << " nodes";
  EXPECT_LT(a.cg_iterations_p50, 1.5 * c.cg_iterations_p50) << a.cg_iterations_p50 << " CG iterations";
  RecordProperty("adaptive_nodes", static_cast<int>(a.nodes));
  RecordProperty("adaptive_cg_iterations_p50", static_cast<int>(a.cg_iterations_p50));
}

// The 8 x 8 x 4 cm block of the Hertz check, the sphere (R 10 cm) stroked 24 mm across its top about 0.25 mm deep,
// the lattice at level 4 refined to 6 within 1 cm of the contact, the jump limit off so nothing masks a step.
std::string stroke_scene(const char* refine) {
  return std::string(R"({
  "mesh": {"box_m": [0.08, 0.08, 0.03996], "box_subdivisions": 32, "size_m": 0.08},
  "grid": {"levels": 6},
  "lattice": {"level": 4, "radius_cells": 8, "fix_floor": true, "integrator": "implicit_euler")") + refine + R"(},
  "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.25, "density_kg_per_m3": 1070, "stiffness_damping_s": 0.02},
  "device": {"max_force_N": 100, "coupling_N_per_m": 300, "coupling_damping_Ns_per_m": 0, "tool_radius_m": 0.1,
             "tool_shape": "sphere", "workspace_half_m": 1.0, "max_stiffness_N_per_m": 300, "jump_limit_N_per_tick": 0},
  "interaction": {"mode": "touch"},
  "trajectory": [{"t_s": 0.0, "pos_m": [0.0, 0.0, 0.2]}]
})";
}

TEST(AdaptiveLattice, MovingTheFineZoneWithTheToolDoesNotStepTheForce) {
  const Scene scene = parse_scene(stroke_scene(R"(, "refine": {"level": 6, "radius_m": 0.01})"), "stroke.json").value();
  const Model model = load_model(scene).value();
  const double top = 0.01998, z = top + 0.1 - 2.5e-4 - 0.2 / 300.0;
  ToolHoldOptions o;
  o.start_pos_m = Vec3(-0.012, 0.0, z);
  o.device_pos_m = Vec3(0.012, 0.0, z);
  o.approach_s = 1.0;
  o.max_s = 1.1;
  o.record_ticks = true;
  auto held = hold_tool(scene, model, o);
  ASSERT_TRUE(held) << held.error().message;
  const ToolHoldResult& h = held.value();
  // the zone (radius 1 cm) moves each time the contact is 5 mm from where it was built: four times over 24 mm
  ASSERT_GE(h.region_move_ticks.size(), 3u);
  const double limit_N = Scene{}.device.jump_limit_N_per_tick;  // the servo's stated jump limit (default)
  double worst = 0.0;
  for (int64_t t : h.region_move_ticks)
    for (int64_t k = std::max<int64_t>(t, 1); k < std::min<int64_t>(t + 17, static_cast<int64_t>(h.tick_force_N.size())); ++k)
      worst = std::max(worst, (h.tick_force_N[static_cast<std::size_t>(k)] - h.tick_force_N[static_cast<std::size_t>(k - 1)]).norm());
  EXPECT_LT(worst, limit_N) << "largest force step in the frames after a zone move";
  // the figures, for --gtest_output=xml (docs/material.md quotes them)
  RecordProperty("zone_moves", static_cast<int>(h.region_move_ticks.size()));
  RecordProperty("largest_step_after_a_move_uN", static_cast<int>(std::lround(1e6 * worst)));
  // and it was pressing all along (a lost contact would be a step too)
  for (int64_t t : h.region_move_ticks) EXPECT_GT(h.tick_force_N[static_cast<std::size_t>(t)].z(), 0.05);
}

}  // namespace
}  // namespace palpate
