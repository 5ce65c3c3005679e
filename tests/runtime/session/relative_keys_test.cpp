// Model-relative keyframes: pos_rel is a point of the model's box, surface snaps onto the surface along the approach,
// so one hand-written scene touches whatever mesh it is given.
#include "runtime/session/relative_keys.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "support/fixtures.h"
#include "support/record_options.h"
#include "runtime/session/device_factory.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {

// A hand-written scene in model-relative keys: above the top centre, down to the surface and 6 mm in, back up.
constexpr const char* kRelativeTouch = R"({
  "mesh": { MESH },
  "lattice": { "level": 4, "fix_floor": true },
  "trajectory": [
    { "t_s": 0.0, "pos_rel": [0.5, 0.5, 1.3] },
    { "t_s": 0.3, "pos_rel": [0.5, 0.5, 1.3] },
    { "t_s": 1.0, "pos_rel": [0.5, 0.5, 0.5], "surface": true, "depth_m": 0.006 },
    { "t_s": 1.5, "pos_rel": [0.5, 0.5, 1.3] }
  ],
  "duration_s": 1.6
})";

Scene relative_scene(const std::string& mesh_json, const std::string& path) {
  std::string text = kRelativeTouch;
  text.replace(text.find("MESH"), 4, mesh_json);
  auto s = parse_scene(text, path);
  EXPECT_TRUE(s) << s.error().message;
  return s.value();
}

TEST(RelativeKeys, PosRelAndSurfaceResolveAgainstTheLoadedModel) {
  // a 100 x 60 x 40 mm box: pos_rel is a point of its box, surface snaps onto the top along the approach
  Scene s = relative_scene(R"("box_m": [0.1, 0.06, 0.04])", "rel.json");
  EXPECT_FALSE(make_device(s, "")) << "unresolved keys are never played as zeros";
  const Model model = load_model(s).value();
  ASSERT_TRUE(resolve_relative_keys(model, &s));
  EXPECT_TRUE(s.trajectory[0].pos_m.isApprox(Vec3(0.0, 0.0, -0.02 + 1.3 * 0.04), 1e-12));
  EXPECT_NEAR(s.trajectory[2].pos_m.z(), 0.02 - 0.006, 1e-12);
  EXPECT_NEAR(s.trajectory[2].pos_m.x(), 0.0, 1e-12);

  // the same scene on the bunny touches it, and so does it on the box: the keys follow the mesh
  for (const std::string& mesh : {R"("file": ")" + test::source_path("scenes/bunny.obj") + R"(", "up_axis": "y")",
                                 std::string(R"("box_m": [0.1, 0.06, 0.04])")}) {
    SCOPED_TRACE(mesh);
    const Scene scene = relative_scene(mesh, "rel.json");
    RecordOptions opt = test::quiet_options("scene_rel", false);
    auto r = record_scene(scene, opt);
    ASSERT_TRUE(r) << r.error().message;
    const auto j = nlohmann::json::parse(r.value().summary_json);
    EXPECT_GT(j["max_force_N"].get<double>(), 0.0);
    EXPECT_GT(j["sim"]["nodes"].get<int>(), 0);
    EXPECT_TRUE(r.value().no_contact.empty()) << r.value().no_contact;
  }
}

TEST(RelativeKeys, SurfaceKeyWhoseApproachMissesTheModelIsAnErrorNamingTheKey) {
  Scene s = relative_scene(R"("box_m": [0.1, 0.06, 0.04])", "miss.json");
  s.trajectory[1].pos_rel = Vec3(3.0, 0.5, 1.3);  // off to the side: the approach runs past the box
  s.trajectory[2].pos_rel = Vec3(3.0, 0.5, 0.5);
  const Model model = load_model(s).value();
  const Status st = resolve_relative_keys(model, &s);
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("scene 'miss.json': trajectory[2]: surface: the approach from"), std::string::npos)
      << st.error().message;
  EXPECT_NE(st.error().message.find("misses the model"), std::string::npos) << st.error().message;
}

}  // namespace
}  // namespace palpate
