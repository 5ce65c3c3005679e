// What a recording's frames show besides the model, end to end: a scripted run's displacement colours take their
// range from a first pass before the first frame (its largest displacement rounded up), the scene's range or
// `none` skip the pass, and a cut's faces show in their colour in the frames of a real cut.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "render/annotate.h"
#include "render/png_io.h"
#include "support/fixtures.h"
#include "support/record_options.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

nlohmann::json record_summary(const Scene& scene, const std::string& tag, std::string* frames = nullptr) {
  RecordOptions opt = test::quiet_options(scene.name + "_" + tag);
  auto r = record_scene(scene, opt);
  EXPECT_TRUE(r) << r.error().message;
  if (!r) return {};
  if (frames) *frames = (fs::path(opt.out_dir) / "frames").string();
  std::ifstream f(r.value().summary_path);
  return nlohmann::json::parse(f);
}

Scene small(const std::string& name) {
  Scene scene = load_scene(test::source_path("scenes/" + name + ".json")).value();
  scene.render.width = 160;
  scene.render.height = 120;
  return scene;
}

TEST(FrameLook, AScriptedRunsColourRangeIsItsLargestDisplacementRoundedUpFixedBeforeTheFirstFrame) {
  const nlohmann::json j = record_summary(small("bunny_touch"), "pass");
  const nlohmann::json& color = j["render"]["color"];
  EXPECT_EQ(color["by"], "displacement");
  EXPECT_TRUE(color["range_fixed"].get<bool>());
  // the surface's largest displacement as the frames drew it (not the lattice's: a node can move farther)
  const double most = color["max_displacement_m"].get<double>();
  ASSERT_GT(most, 0.0);
  EXPECT_LE(most, j["max_displacement_m"].get<double>());
  EXPECT_EQ(color["range_m"].get<double>(), nice_ceil(most)) << "largest displacement " << most;
  // the scene's own range is kept (no pass), and `none` colours nothing
  Scene given = small("bunny_touch");
  given.render.color_range_m = 0.02;
  given.duration_s = 0.2;
  EXPECT_EQ(record_summary(given, "given")["render"]["color"]["range_m"].get<double>(), 0.02);
  Scene plain = small("bunny_touch");
  plain.render.color = RenderColor::kNone;
  plain.duration_s = 0.2;
  const nlohmann::json p = record_summary(plain, "plain")["render"]["color"];
  EXPECT_EQ(p["by"], "none");
  EXPECT_EQ(p["range_m"].get<double>(), 0.0);
}

// Pixels of a frame in the cut's colour as the light shades it: red and blue both well above green.
int cut_colored_px(const Image& im) {
  int n = 0;
  for (std::size_t i = 0; i + 3 < im.rgba.size(); i += 4) {
    const int r = im.rgba[i], g = im.rgba[i + 1], b = im.rgba[i + 2];
    n += r - g > 60 && b - g > 20 && r > b ? 1 : 0;
  }
  return n;
}

TEST(FrameLook, TheFacesACutMakesShowInTheirColour) {
  Scene scene = load_scene(test::source_path("scenes/bunny_cut.json")).value();
  scene.render.legend = false;  // its swatch is in the cut's colour
  std::string frames;
  const nlohmann::json j = record_summary(scene, "faces", &frames);
  ASSERT_GT(j["cut"]["vertices_added"].get<int64_t>(), 0);
  // cut mode colours no displacement (a piece cut free moves as a body) but the cut's faces
  EXPECT_EQ(j["render"]["color"]["by"], "none");
  const int64_t last = j["frames_written"].get<int64_t>() - 1;
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05lld.png", static_cast<long long>(last));
  const auto first = read_png((fs::path(frames) / "frame_00000.png").string());
  const auto end = read_png((fs::path(frames) / name).string());
  ASSERT_TRUE(first && end);
  EXPECT_EQ(cut_colored_px(first.value()), 0);
  EXPECT_GT(cut_colored_px(end.value()), 100) << name;
}

// Coloured by strain: the range comes from the first pass as the displacement's does (the largest strain the frames
// drew, rounded up), and the summary says what the colours show.
TEST(FrameLook, StrainColoursTakeTheirRangeFromAFirstPass) {
  Scene scene = small("bunny_pull");
  scene.render.color = RenderColor::kStrain;
  const nlohmann::json color = record_summary(scene, "strain")["render"]["color"];
  EXPECT_EQ(color["by"], "strain");
  EXPECT_TRUE(color["range_fixed"].get<bool>());
  const double most = color["max_strain"].get<double>();
  ASSERT_GT(most, 0.01);
  EXPECT_EQ(color["range"].get<double>(), nice_ceil(most)) << "largest strain " << most;
}

// Framed whole, a run's model and its tool stay inside every frame: with nothing else drawn (no floor, insets or
// arrow), the outermost ring of pixels of every frame of the shipped scenes that frame the whole model is the
// background (block_stroke's and phantom_press's 6 mm spheres start above the block, where a frame of the model
// alone cut them off).
TEST(FrameLook, EveryFrameOfAWholeModelRunKeepsTheModelAndTheToolInsideThePicture) {
  for (const char* name : {"bunny_pull", "bunny_touch", "cube_press", "tissue_pull", "block_stroke", "phantom_press"}) {
    Scene scene = small(name);
    ASSERT_FALSE(scene.render.frame_radius_m > 0.0) << name;
    scene.duration_s = std::min(scene.duration_s, 3.0);
    scene.render.color = RenderColor::kNone;
    scene.render.force_arrow = scene.render.legend = scene.render.floor = scene.render.force_trace = false;
    scene.render.antialias = 0;
    std::string frames;
    const nlohmann::json j = record_summary(scene, "framed", &frames);
    const int64_t n = j["frames_written"].get<int64_t>();
    ASSERT_GT(n, 0) << name;
    int64_t touching = 0;
    for (int64_t f = 0; f < n; ++f) {
      char file[32];
      std::snprintf(file, sizeof file, "frame_%05lld.png", static_cast<long long>(f));
      const auto im = read_png((fs::path(frames) / file).string());
      ASSERT_TRUE(im) << name << " " << file;
      const Image& m = im.value();
      auto bg = [&](int x, int y) {
        const uint8_t* p = &m.rgba[(static_cast<std::size_t>(y) * m.width + x) * 4];
        return p[0] == 247 && p[1] == 247 && p[2] == 250;
      };
      bool ring = true;
      for (int x = 0; x < m.width; ++x) ring = ring && bg(x, 0) && bg(x, m.height - 1);
      for (int y = 0; y < m.height; ++y) ring = ring && bg(0, y) && bg(m.width - 1, y);
      touching += ring ? 0 : 1;
    }
    EXPECT_EQ(touching, 0) << name << ": frames whose edge the model reaches, of " << n;
  }
}

}  // namespace
}  // namespace palpate
