// Models whose faces are wound inward, or with a patch wound against its neighbours, are turned outward at load:
// the tool pressing on them from outside touches them, and the blade drawn through them is felt.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/mesh_io.h"
#include "core/scene.h"
#include "support/fixtures.h"
#include "support/json_file.h"
#include "support/record_options.h"
#include "runtime/record/recorder.h"
#include "runtime/session/model.h"

namespace palpate {
namespace {

// a 100 mm box of 192 triangles written as OBJ; `turned` says which triangles are written wound the other way
template <typename Turned>
std::string write_box_obj(const std::string& dir, const std::string& name, Turned turned) {
  const TriMesh box = make_box_mesh(Vec3::Constant(0.1), 4);
  std::string text;
  char line[96];
  for (const Vec3& v : box.vertices_m) {
    std::snprintf(line, sizeof line, "v %.6f %.6f %.6f\n", v.x(), v.y(), v.z());
    text += line;
  }
  for (std::size_t t = 0; t < box.triangles.size(); ++t) {
    std::array<int32_t, 3> f = box.triangles[t];
    Vec3 centre = Vec3::Zero();
    for (int32_t v : f) centre += box.vertices_m[static_cast<std::size_t>(v)] / 3.0;
    if (turned(centre)) std::swap(f[1], f[2]);
    std::snprintf(line, sizeof line, "f %d %d %d\n", f[0] + 1, f[1] + 1, f[2] + 1);
    text += line;
  }
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/" + name;
  test::write_text(path, text);
  return path;
}

// the tool comes down on the top face 6 mm beside its centre (the file's z is up), presses 10 mm in (touch) or
// strokes 40 mm across at that depth with the button held (cut)
RecordResult press_or_cut(const std::string& mesh, const std::string& mode, const std::string& out) {
  const std::string cut = mode == "cut" ? R"(, "button": true)" : "";
  const std::string text = R"({ "mesh": { "file": ")" + mesh + R"(", "size_m": 0.1, "up_axis": "z" },
    "grid": { "levels": 4 },
    "lattice": { "level": 4, "node_mass_kg": 0.001, "gravity_m_per_s2": [0, 0, 0], "fix_floor": true },
    "interaction": { "mode": ")" + mode + R"(", "blade_length_m": 0.05 },
    "trajectory": [ { "t_s": 0.0, "pos_m": [-0.02, 0.006, 0.07])" + cut + R"( },
                    { "t_s": 0.3, "pos_m": [-0.02, 0.006, 0.04])" + cut + R"( },
                    { "t_s": 0.6, "pos_m": [0.02, 0.006, 0.04])" + cut + R"( } ],
    "duration_s": 0.6 })";
  RecordOptions opt = test::quiet_options(out, false);
  return record_scene(parse_scene(text, out + ".json").value(), opt).value();
}

TEST(ModelOrientation, InvertedAndPatchFlippedModelsAreTouchedAndCutFromOutside) {
  const std::string dir = test::fresh_dir("orientation_models");
  const std::string inverted = write_box_obj(dir, "inverted.obj", [](const Vec3&) { return true; });
  // the top face's triangles under and around the tool (x < 0.01 m), wound against the rest
  const std::string patched = write_box_obj(dir, "patched.obj", [](const Vec3& c) { return c.z() > 0.049 && c.x() < 0.01; });
  struct Case { std::string mesh, notice; };
  for (const Case& c : {Case{inverted, "turned 192 of 192 triangles outward: 1 closed part wound inside out"},
                        Case{patched, "turned 20 of 192 triangles outward: 1 part with faces wound against their "
                                      "neighbours across shared edges"}}) {
    for (const std::string mode : {"touch", "cut"}) {
      const RecordResult r = press_or_cut(c.mesh, mode, "orientation_" + mode);
      const auto j = nlohmann::json::parse(r.summary_json);
      EXPECT_EQ(r.no_contact, "") << c.mesh << " " << mode;
      EXPECT_GT(j["max_force_N"].get<double>(), 0.1) << c.mesh << " " << mode;
      EXPECT_EQ(r.mesh_notice, c.notice) << c.mesh << " " << mode;
      EXPECT_EQ(j["model"]["orientation"], c.notice);
      if (mode == "cut") {
        EXPECT_GT(j["cut"]["springs_cut"].get<int>(), 0);
      }
    }
  }
}

TEST(ModelOrientation, AnOutwardModelLoadsUnchanged) {
  const std::string dir = test::fresh_dir("orientation_outward");
  const std::string path = write_box_obj(dir, "box.obj", [](const Vec3&) { return false; });
  Scene s;
  s.mesh.file = path;
  s.mesh.up_axis = 'z';
  const Model m = load_model(s).value();
  EXPECT_FALSE(m.orientation.changed());
  EXPECT_EQ(m.orientation.notice(), "");
  EXPECT_EQ(m.orientation.closed_components, 1);
}

}  // namespace
}  // namespace palpate
