// The frame stage driven by hand-made servo samples: a contact sliding across a box moves the region several
// times, and after every frame the normals it keeps (recomputed only where the region reaches) equal a
// recomputation of the whole mesh bit for bit.
#include "runtime/session/frame_stage.h"

#include <gtest/gtest.h>

#include "core/aabb.h"
#include "core/tri_mesh.h"
#include "render/gl_context.h"
#include "render/gl_context_factory.h"
#include "render/renderer.h"
#include "support/fixtures.h"
#include "support/pressed_box.h"

namespace palpate {
namespace {

constexpr const char* kBox = test::kPressedBoxScene;

TEST(FrameStage, NormalsKeptOnlyWhereTheRegionReachesEqualTheWholeMeshs) {
  const Scene scene = parse_scene(kBox, "box.json").value();
  const Model model = load_model(scene).value();
  SpscQueue<HapticSample> samples(4096);
  TripleBuffer<LocalModel> local;
  FrameStage stage(scene, model, &samples, &local, nullptr, nullptr, nullptr);
  int64_t tick = 0, mismatched_frames = 0;
  for (int f = 0; f < 90; ++f) {
    // pressed 0.6 N into the top, sliding from x = -2 cm to +2 cm over the first 60 frames, then released
    const double x = -0.02 + 0.04 * std::min(f, 60) / 60.0;
    Vec3 c = Vec3::Zero();
    const int32_t tri = test::top_triangle_near(model.rest, x, 0.0, &c);
    ASSERT_GE(tri, 0);
    for (int k = 0; k < 16; ++k) {
      HapticSample s;
      s.tick = tick++;
      s.t_s = s.tick * 1e-3;
      s.tool_pos_m = c - Vec3(0, 0, 0.002);
      s.proxy_pos_m = c;
      if (f < 60) {
        s.contact = ContactState::kTouch;
        s.contact_tri = tri;
        s.contact_bary = Vec3::Constant(1.0 / 3.0);
        s.force_N = Vec3(0, 0, 0.6);
      }
      ASSERT_TRUE(samples.try_push(s));
    }
    stage.frame(f, f / 60.0, true);
    std::vector<Vec3> full;
    compute_vertex_normals(stage.vertices_m(), stage.triangles(), &full);
    ASSERT_EQ(full.size(), stage.normals().size());
    bool same = true;
    for (std::size_t v = 0; v < full.size(); ++v) same = same && (full[v].array() == stage.normals()[v].array()).all();
    mismatched_frames += same ? 0 : 1;
  }
  EXPECT_EQ(mismatched_frames, 0);
  EXPECT_GE(stage.stats().region_moves, 2);
  EXPECT_GT(stage.stats().max_displacement_m, 1e-4);
}

// A box finer than a 64 x 48 image is drawn clustered (a MeshLod: its own triangles over some of the mesh's
// vertices, shaded with the whole mesh's normals). The renderer redraws only the vertices a view names as
// moving and those on a triangle with one; every other vertex it draws must keep its position and normal until
// the view's layer epoch changes. Vertices that change shade without moving (their neighbours in the whole
// mesh move) are among those redrawn.
TEST(FrameStage, AClusteredViewRedrawsEveryVertexWhoseShadeCanChange) {
  Scene scene = parse_scene(kBox, "box.json").value();
  scene.mesh.box_subdivisions = 48;
  scene.render.width = 64;
  scene.render.height = 48;
  const Model model = load_model(scene).value();
  auto ctx = create_gl_context(64, 48, RenderBackend::kAuto);
  ASSERT_TRUE(ctx.ok()) << ctx.error().message;
  const Aabb box = Aabb::of(model.rest.vertices_m);
  Renderer renderer(ctx.value().get(), RenderStyle::kSolid, Camera::framing(box.min_m, box.max_m, 64.0 / 48.0));
  SpscQueue<HapticSample> samples(4096);
  TripleBuffer<LocalModel> local;
  FrameStage stage(scene, model, &samples, &local, &renderer, nullptr, nullptr);
  ASSERT_NE(stage.lod(), nullptr);
  std::vector<Vec3> last_v = stage.vertices_m(), last_n = stage.normals();
  uint64_t last_epoch = stage.current_view().layer_epoch;
  int64_t tick = 0, not_redrawn = 0, shade_only = 0;
  std::vector<uint8_t> redrawn(model.rest.vertices_m.size());
  for (int f = 0; f < 40; ++f) {
    Vec3 c = Vec3::Zero();
    const int32_t tri = test::top_triangle_near(model.rest, 0.004, 0.002, &c);
    ASSERT_GE(tri, 0);
    for (int k = 0; k < 16; ++k) ASSERT_TRUE(samples.try_push(test::pressed_sample(tick++, tri, c)));
    stage.frame(f, f / 60.0, true);
    const FrameView view = stage.current_view();
    ASSERT_EQ(view.triangles, &stage.lod()->triangles);
    ASSERT_NE(view.moving_vertices, nullptr);
    // what the renderer redraws: the named vertices and the others of their clustered triangles
    std::fill(redrawn.begin(), redrawn.end(), 0);
    std::vector<uint8_t> named(redrawn.size(), 0);
    for (int32_t v : *view.moving_vertices) named[v] = 1;
    for (const auto& t : *view.triangles)
      if (named[t[0]] || named[t[1]] || named[t[2]]) redrawn[t[0]] = redrawn[t[1]] = redrawn[t[2]] = 1;
    if (view.layer_epoch == last_epoch) {
      for (const auto& t : *view.triangles)
        for (int32_t v : t) {
          const bool moved = (stage.vertices_m()[v].array() != last_v[v].array()).any();
          const bool shaded = (stage.normals()[v].array() != last_n[v].array()).any();
          not_redrawn += (moved || shaded) && !redrawn[v] ? 1 : 0;
          shade_only += shaded && !moved ? 1 : 0;
        }
    }
    last_v = stage.vertices_m();
    last_n = stage.normals();
    last_epoch = view.layer_epoch;
  }
  EXPECT_EQ(not_redrawn, 0);
  EXPECT_GT(shade_only, 0);  // the case the test is about happened
  EXPECT_GT(stage.stats().max_displacement_m, 1e-4);
}

TEST(FrameStage, ContactModelWaitsOneFrameAfterTheRegionIsPlacedOrMoved) {
  // the sliding contact of the test above: on the frame that places the region and on each that moves it the servo
  // gets no contact model (the compliance factor waits a frame), on every other frame in contact it gets one
  const Scene scene = parse_scene(kBox, "box.json").value();
  const Model model = load_model(scene).value();
  SpscQueue<HapticSample> samples(4096);
  TripleBuffer<LocalModel> local;
  FrameStage stage(scene, model, &samples, &local, nullptr, nullptr, nullptr);
  int64_t tick = 0, moves = 0, without = 0, with = 0;
  for (int f = 0; f < 60; ++f) {
    const double x = -0.02 + 0.04 * f / 60.0;
    Vec3 c = Vec3::Zero();
    const int32_t tri = test::top_triangle_near(model.rest, x, 0.0, &c);
    ASSERT_GE(tri, 0);
    for (int k = 0; k < 16; ++k) {
      ASSERT_TRUE(samples.try_push(test::pressed_sample(tick++, tri, c)));
    }
    const bool had_lattice = stage.lattice().has_value();
    stage.frame(f, f / 60.0, true);
    const bool changed = !had_lattice || stage.stats().region_moves > moves;
    moves = stage.stats().region_moves;
    const LocalModel& m = local.read();
    ASSERT_EQ(m.frame, stage.stats().frames - 1);
    EXPECT_EQ(m.has_contact_model, !changed) << "frame " << f;
    (m.has_contact_model ? with : without) += 1;
    if (m.has_contact_model) {
      EXPECT_GT(m.compliance_m_per_N.trace(), 0.0) << "frame " << f;
    }
  }
  EXPECT_GE(moves, 2);
  EXPECT_EQ(without, 1 + moves);
  EXPECT_EQ(with, 60 - without);
}

// A clock that advances by a fixed step at every reading: each mark of a frame costs that much.
class SteppingClock final : public BudgetClock {
 public:
  explicit SteppingClock(double step_ms) : step_ms_(step_ms) {}
  double now_ms() override { return t_ms_ += step_ms_; }

 private:
  double step_ms_;
  double t_ms_ = 0.0;
};

// Runs the box pressed for 40 frames with local_global; returns the stage's state hash.
std::string pressed_box(const Scene& scene, const Model& model, BudgetClock* clock, FrameStats* stats,
                        std::vector<int64_t>* frames_at) {
  SpscQueue<HapticSample> samples(4096);
  TripleBuffer<LocalModel> local;
  FrameStage stage(scene, model, &samples, &local, nullptr, nullptr, nullptr);
  if (clock) stage.use_budget(clock);
  Vec3 c = Vec3::Zero();
  const int32_t tri = test::top_triangle_near(model.rest, 0.0, 0.0, &c);
  int64_t tick = 0;
  for (int f = 0; f < 40; ++f) {
    for (int k = 0; k < 16; ++k) {
      EXPECT_TRUE(samples.try_push(test::pressed_sample(tick++, tri, c)));
    }
    stage.frame(f, f / 60.0, true);
  }
  *stats = stage.stats();
  if (stage.budget()) *frames_at = stage.budget()->frames_at();
  return stage.state_hash();
}

TEST(FrameStage, BudgetStepsWithTheSettingItsClockAllows) {
  std::string json = kBox;
  const std::string key = "\"fix_floor\": true";
  json.replace(json.find(key), key.size(), key + ", \"integrator\": \"local_global\", \"budget_ms\": 8");
  const Scene scene = parse_scene(json, "box.json").value();
  const Model model = load_model(scene).value();
  FrameStats plain, idle, loaded;
  std::vector<int64_t> at_idle, at_loaded, none;
  const std::string h_plain = pressed_box(scene, model, nullptr, &plain, &none);
  EXPECT_TRUE(none.empty());  // no clock, no budget
  // a clock that hardly moves: every frame holds 8 ms at the scene's 10 iterations, the same run as without
  SteppingClock cheap(0.01);
  EXPECT_EQ(pressed_box(scene, model, &cheap, &idle, &at_idle), h_plain);
  ASSERT_EQ(at_idle.size(), 6u);
  EXPECT_EQ(at_idle[0], 40);
  // 5 ms a reading (4 readings a stepped frame): the step alone costs 5 ms, its frame 15 ms; every rung predicts
  // more than 8 ms, so after the first frame the cheapest (1 iteration) runs, and the run differs
  SteppingClock dear(5.0);
  EXPECT_NE(pressed_box(scene, model, &dear, &loaded, &at_loaded), h_plain);
  ASSERT_EQ(at_loaded.size(), 6u);
  EXPECT_EQ(at_loaded[0], 1);
  EXPECT_EQ(at_loaded[5], 39);
  EXPECT_EQ(loaded.frames_stepped, plain.frames_stepped);
}

// Under a frame budget a cut takes at most kBudgetSpringsPerFrame springs out of the lattice a frame (each costs
// the factor a downdate before the step); without one (lockstep: reproducible) a cut takes all it crosses.
TEST(FrameStage, ABudgetLimitsTheSpringsACutTakesOutAFrame) {
  const Scene scene = load_scene(test::source_path("scenes/bunny_cut.json")).value();
  const Model model = load_model(scene).value();
  SpscQueue<HapticSample> samples(16);
  TripleBuffer<LocalModel> local;
  FrameStage plain(scene, model, &samples, &local, nullptr, nullptr, nullptr);
  const CutModel* plain_cut = plain.cut_model();
  ASSERT_NE(plain_cut, nullptr);
  EXPECT_EQ(plain_cut->max_springs_per_apply(), 0);
  FrameStage budgeted(scene, model, &samples, &local, nullptr, nullptr, nullptr);
  SteppingClock clock(0.01);
  budgeted.use_budget(&clock);
  ASSERT_NE(budgeted.budget(), nullptr);
  const CutModel* budgeted_cut = budgeted.cut_model();
  ASSERT_NE(budgeted_cut, nullptr);
  EXPECT_EQ(budgeted_cut->max_springs_per_apply(), kBudgetSpringsPerFrame);
  EXPECT_DOUBLE_EQ(budgeted.budget()->plan_ms(), kFramePlanFraction * scene.lattice.budget_ms);
}

// bunny_cut's body rests in its own shape and steps nothing until a piece comes free: under a budget, warm_up()
// finds no lattice to measure (no dry step, no factorisation before the first frame) and the first frames step
// nothing; the run is the plain run.
TEST(FrameStage, ACutSceneStepsNothingBeforeAPieceComesFreeAndItsWarmUpMeasuresNothing) {
  const Scene scene = load_scene(test::source_path("scenes/bunny_cut.json")).value();
  ASSERT_GT(scene.lattice.budget_ms, 0.0);
  const Model model = load_model(scene).value();
  auto run = [&](BudgetClock* clock, bool warm, int frames) {
    SpscQueue<HapticSample> samples(16);
    TripleBuffer<LocalModel> local;
    FrameStage stage(scene, model, &samples, &local, nullptr, nullptr, nullptr);
    if (clock) stage.use_budget(clock);
    if (warm) stage.warm_up();
    for (int f = 0; f < frames; ++f) stage.frame(f, f / 60.0, true);
    EXPECT_EQ(stage.stats().frames_stepped, 0);
    EXPECT_EQ(stage.stats().frames_resting, frames);
    EXPECT_TRUE(stage.stats().step_cpu_ms.empty());
    return stage.state_hash();
  };
  SteppingClock dear(5.0);
  EXPECT_EQ(run(&dear, true, 3), run(nullptr, false, 3));
}

}  // namespace
}  // namespace palpate
