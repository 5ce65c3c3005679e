// FrameStage::warm_up, which a realtime run calls before its clock starts: it draws the current state once into a
// buffer of its own, so nothing is written for it, and the frames drawn afterwards are byte for byte those of a
// stage that never warmed up (the layered path included: the box is pressed, so a lattice region forms).
#include <gtest/gtest.h>

#include <filesystem>

#include "render/gl_context_factory.h"
#include "render/png_writer.h"
#include "render/renderer.h"
#include "support/fixtures.h"
#include "support/pressed_box.h"
#include "support/read_file.h"
#include "runtime/session/frame_stage.h"

namespace palpate {
namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 20;

struct PressRun {
  int64_t draws_before_first_frame = 0;  // renderer draws made before frame 0
  int written_before_first_frame = 0;    // files the writer had written before frame 0
  int written = 0;
  int64_t layered = 0;
};

// The box pressed at the centre of its top face for kFrames frames, drawn into dir; warm: warm_up() first.
PressRun pressed_box(const std::string& dir, bool warm) {
  Scene scene = parse_scene(test::kPressedBoxScene, "box.json").value();
  scene.render.width = 96;
  scene.render.height = 72;
  scene.render.style = RenderStyle::kBoth;
  scene.render.backend = RenderBackend::kOsmesa;
  const Model model = load_model(scene).value();
  auto ctx = create_gl_context(scene.render.width, scene.render.height, RenderBackend::kOsmesa);
  EXPECT_TRUE(ctx) << ctx.error().message;
  const auto& box = model.rest;
  Vec3 lo = box.vertices_m[0], hi = box.vertices_m[0];
  for (const Vec3& v : box.vertices_m) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  Renderer renderer(ctx.value().get(), scene.render.style,
                    Camera::framing(lo, hi, static_cast<double>(scene.render.width) / scene.render.height));
  fs::create_directories(dir);
  PngWriter writer(dir, scene.render.width, scene.render.height, 3);
  SpscQueue<HapticSample> samples(4096);
  TripleBuffer<LocalModel> local;
  FrameStage stage(scene, model, &samples, &local, &renderer, &writer, nullptr);
  PressRun r;
  if (warm) stage.warm_up();
  r.draws_before_first_frame = renderer.draws();
  r.written_before_first_frame = writer.frames_written();
  Vec3 c = Vec3::Zero();
  const int32_t tri = test::top_triangle_near(box, 0.0, 0.0, &c);
  EXPECT_GE(tri, 0);
  int64_t tick = 0;
  for (int f = 0; f < kFrames; ++f) {
    for (int k = 0; k < 16; ++k) {
      EXPECT_TRUE(samples.try_push(test::pressed_sample(tick++, tri, c)));
    }
    stage.frame(f, f / 60.0, true);
  }
  writer.finish();
  r.written = writer.frames_written();
  r.layered = stage.stats().frames_layered;
  return r;
}

TEST(FrameStage, WarmUpDrawsOnceWritesNothingAndLeavesEveryFrameUnchanged) {
  const std::string cold_dir = test::fresh_dir("warm_up_cold"), warm_dir = test::fresh_dir("warm_up_warm");
  const PressRun cold = pressed_box(cold_dir, false);
  const PressRun warm = pressed_box(warm_dir, true);
  EXPECT_EQ(cold.draws_before_first_frame, 0);
  EXPECT_EQ(warm.draws_before_first_frame, 1);  // it did draw
  EXPECT_EQ(warm.written_before_first_frame, 0);  // and wrote nothing
  ASSERT_EQ(cold.written, kFrames);
  ASSERT_EQ(warm.written, kFrames);
  EXPECT_GT(warm.layered, 0);  // the cached-layer path ran after the warm-up
  int differing = 0;
  for (const auto& entry : fs::directory_iterator(cold_dir)) {
    const fs::path other = fs::path(warm_dir) / entry.path().filename();
    ASSERT_TRUE(fs::exists(other)) << other;
    differing += test::read_file(entry.path()) == test::read_file(other) ? 0 : 1;
  }
  EXPECT_EQ(differing, 0);
}

}  // namespace
}  // namespace palpate
