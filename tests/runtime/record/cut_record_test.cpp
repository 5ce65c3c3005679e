// Cut mode end to end: scene keys, the servo's blade report and resistance, and cut recordings through the
// lockstep pipeline (deterministic, valid mesh, springs cut).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "haptics/devices/scripted_device.h"
#include "haptics/servo/servo.h"
#include "render/png_io.h"
#include "sim/cut/mesh_split.h"
#include "support/fixtures.h"
#include "support/haptic_fixtures.h"
#include "support/record_options.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/model.h"
#include "runtime/record/recorder.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

using test::fresh_dir;

// A block with a blade drawn through it along x while the button is held; the blade axis is tilted to +y.
Scene block_cut_scene(double blade_z_m) {
  const std::string text = R"({
    "mesh": { "box_m": [0.06, 0.06, 0.06], "box_subdivisions": 6, "size_m": 0.06 },
    "grid": { "levels": 4 },
    "lattice": { "level": 3, "node_mass_kg": 0.001, "stiffness_N_per_m": { "structural": 40, "shear": 20, "bend": 10 },
                 "damping_Ns_per_m": 0.05, "gravity_m_per_s2": [0, 0, -9.81], "fix_floor": true },
    "interaction": { "mode": "cut", "blade_length_m": 0.1, "cut_resistance_Ns_per_m": 5 },
    "trajectory": [
      { "t_s": 0.0, "pos_m": [0.05, -0.05, Z], "button": true, "orientation_wxyz": [0.70710678, -0.70710678, 0, 0] },
      { "t_s": 0.5, "pos_m": [-0.05, -0.05, Z], "orientation_wxyz": [0.70710678, -0.70710678, 0, 0] }
    ],
    "render": { "width": 64, "height": 48 },
    "duration_s": 0.7
  })";
  std::string t = text;
  const std::string z = std::to_string(blade_z_m);
  for (std::size_t at = t.find('Z'); at != std::string::npos; at = t.find('Z')) t.replace(at, 1, z);
  return parse_scene(t, "block_cut.json").value();
}

RecordResult record(const Scene& scene, const std::string& name, bool render = false) {
  RecordOptions opt = test::quiet_options(name, render);
  return record_scene(scene, opt).value();
}

TEST(CutScene, ParsesModeBladeAndOrientation) {
  const Scene s = block_cut_scene(0.013);
  EXPECT_EQ(s.mode, InteractionMode::kCut);
  EXPECT_STREQ(mode_name(s.mode), "cut");
  EXPECT_DOUBLE_EQ(s.blade_length_m, 0.1);
  EXPECT_NEAR((s.trajectory[0].orientation * Vec3::UnitZ() - Vec3::UnitY()).norm(), 0.0, 1e-7);
  auto bad = parse_scene(R"({"mesh": {"box_m": [0.1, 0.1, 0.1]},
                             "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0], "orientation_wxyz": [0, 0, 0, 0]}]})",
                         "b.json");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("trajectory[0].orientation_wxyz"), std::string::npos) << bad.error().message;
}

TEST(CutServo, ReportsTheBladeAndResistsItsMotionInsideTheMaterialOnly) {
  const Scene s = block_cut_scene(0.013);
  ServoParams p;
  p.mode = InteractionMode::kCut;
  p.blade_length_m = s.blade_length_m;
  p.cut_resistance_Ns_per_m = 5.0;
  p.ramp_s = 0.0;
  test::ServoRig<ScriptedDevice> rig(p, 4096, test::kTestRates, DeviceSpecs{}, s.hand, s.trajectory);  // at 1 kHz
  {
    // a wall at x = 0 facing +x, which the blade (moving toward -x) enters
    LocalModel& m = rig.tb->write_buffer();
    const Vec3 a(0, -0.2, -0.2), b(0, 0.2, -0.2), c(0, 0.2, 0.2), d(0, -0.2, 0.2);
    m.num_triangles = 2;
    m.tri_m[0] = {a, b, c};
    m.tri_m[1] = {a, c, d};
    m.normal[0] = m.normal[1] = {Vec3::UnitX(), Vec3::UnitX(), Vec3::UnitX()};
    m.frame = 0;
    rig.tb->publish();
  }
  bool saw_outside = false, saw_inside = false;
  for (int i = 0; i < 450; ++i) {
    rig.tick(i);
    const HapticSample& smp = rig.servo->last_sample();
    EXPECT_NEAR((smp.blade_axis - Vec3::UnitY()).norm(), 0.0, 1e-6);
    EXPECT_LE(smp.force_N.norm(), DeviceSpecs{}.max_force_N + 1e-12);
    if (i < 20) continue;  // the hand gets going
    if (smp.tool_pos_m.x() > 0.001) {
      saw_outside = true;
      EXPECT_EQ(smp.contact, ContactState::kFree);
      EXPECT_EQ(smp.force_N.norm(), 0.0);
    } else if (smp.tool_pos_m.x() < -0.001) {
      saw_inside = true;
      EXPECT_EQ(smp.contact, ContactState::kCut);
      EXPECT_GT(smp.force_N.x(), 0.0);  // against the motion
    }
  }
  EXPECT_TRUE(saw_outside && saw_inside);
}

TEST(CutRecord, CuttingTheBlockThroughSeparatesItDeterministically) {
  const Scene s = block_cut_scene(0.013);
  const RecordResult a = record(s, "cut_a");
  const RecordResult b = record(s, "cut_b");
  EXPECT_EQ(a.state_hash, b.state_hash);
  EXPECT_FALSE(a.state_hash.empty());
  const auto j = nlohmann::json::parse(a.summary_json);
  EXPECT_EQ(j["interaction"], "cut");
  EXPECT_GT(j["cut"]["springs_cut"].get<int>(), 0);
  EXPECT_GT(j["cut"]["triangles_added"].get<int>(), 0);
  EXPECT_GT(j["cut"]["free_nodes"].get<int>(), 0);  // the top comes free of the floor's nodes
  EXPECT_EQ(j["nan_events"].get<int>(), 0);
  EXPECT_GT(j["max_force_N"].get<double>(), 0.0);  // the blade's resistance
}

// The cut mesh's update (CutModel::deform) writes every one of its vertices, and the blade's splits add vertices:
// a stepped frame counts the mesh's vertex count after that frame's splits, a resting frame counts none, and the
// summary's sim.per_frame_mean.vertices and sim.vertices are the mean and the largest of those counts.
TEST(CutRecord, VerticesCountedPerFrameAreTheCutMeshsAsItGrows) {
  const Scene s = block_cut_scene(0.013);
  const Model model = load_model(s).value();
  auto device = make_device(s, "").value();
  Session session(s, model, device.get());
  const FrameStats& st = session.stage().stats();
  int64_t counted = 0, stepped = 0, sum = 0;
  std::size_t largest = 0;
  session.run_lockstep(s.duration_s, [&](int64_t f, double) {
    const std::size_t n = session.stage().vertices_m().size();
    const bool was_stepped = st.frames_stepped > stepped;
    EXPECT_EQ(st.vertex_frames - counted, was_stepped ? static_cast<int64_t>(n) : 0) << "frame " << f;
    if (was_stepped) sum += static_cast<int64_t>(n), largest = std::max(largest, n);
    counted = st.vertex_frames;
    stepped = st.frames_stepped;
  });
  ASSERT_GT(stepped, 0);
  EXPECT_GT(session.stage().vertices_m().size(), model.rest.vertices_m.size()) << "the blade split no vertex";

  // the same run through the recorder: its summary reports those figures
  const RecordResult r = record(s, "cut_vertices");
  EXPECT_EQ(r.state_hash, session.stage().state_hash());
  const auto j = nlohmann::json::parse(r.summary_json);
  EXPECT_DOUBLE_EQ(j["sim"]["per_frame_mean"]["vertices"].get<double>(),
                   static_cast<double>(sum) / static_cast<double>(st.frames));
  EXPECT_EQ(j["sim"]["vertices"].get<std::size_t>(), largest);
  EXPECT_EQ(largest, model.rest.vertices_m.size() + j["cut"]["vertices_added"].get<std::size_t>());
}

// A box of 12 triangles (a CAD part's large faces): the blade goes 10 mm into the top face, 40 mm or more from every
// vertex, and strokes 30 mm across it without crossing an edge (no split brings a vertex near). The servo's patch
// holds the face the blade crosses: a face larger than the patch's box, with no vertex in it, was left out, and the
// cut was never felt (max force 0, "no contact", as on assimp's box.obj and cube_uv.ply).
TEST(CutRecord, ABladeInsideOneLargeFaceIsFelt) {
  const Scene s = parse_scene(R"({
    "mesh": { "box_m": [0.1, 0.1, 0.1], "box_subdivisions": 1, "size_m": 0.1 },
    "grid": { "levels": 4 },
    "lattice": { "level": 4, "node_mass_kg": 0.001, "gravity_m_per_s2": [0, 0, 0], "fix_floor": true },
    "interaction": { "mode": "cut", "blade_length_m": 0.05, "cut_resistance_Ns_per_m": 4 },
    "trajectory": [
      { "t_s": 0.0, "pos_m": [0.01, 0.004, 0.08], "button": true },
      { "t_s": 0.3, "pos_m": [0.01, 0.004, 0.04], "button": true },
      { "t_s": 0.8, "pos_m": [0.04, 0.004, 0.04], "button": true }
    ],
    "duration_s": 0.8
  })", "big_faces.json").value();
  ASSERT_EQ(load_model(s).value().rest.triangles.size(), 12u);
  const RecordResult r = record(s, "cut_big_faces");
  const auto j = nlohmann::json::parse(r.summary_json);
  EXPECT_GT(j["cut"]["springs_cut"].get<int>(), 0);
  EXPECT_GT(j["max_force_N"].get<double>(), 0.0);  // the blade's resistance inside the material
  EXPECT_EQ(r.no_contact, "");
}

TEST(CutRecord, BladeDrawnAboveTheBlockChangesNothing) {
  Scene s = block_cut_scene(0.013);
  Scene above = block_cut_scene(0.08);
  Scene none = block_cut_scene(0.08);
  for (auto& k : none.trajectory) k.button = false;
  EXPECT_EQ(record(above, "cut_above").state_hash, record(none, "cut_none").state_hash);
  EXPECT_NE(record(s, "cut_through").state_hash, record(none, "cut_none2").state_hash);
}

// A slit 8 mm deep along the top of a block, without gravity (nothing moves but what the cut changes), recorded with
// frames: the last frame (blade lifted out of view) differs from that of the same stroke with the button never held
// along the blade's path, because the split's copies are sunk into a groove (cut_incision.h). Without the groove
// (kIncisionDepthCells = 0) the split mesh draws exactly as the uncut one and the frames are the same.
TEST(CutRecord, ASlitThatDoesNotOpenIsSeenAlongTheBladesPath) {
  auto slit_scene = [](bool button) {
    std::string t = R"({
      "mesh": { "box_m": [0.06, 0.06, 0.06], "box_subdivisions": 12, "size_m": 0.06 },
      "grid": { "levels": 4 },
      "lattice": { "level": 4, "node_mass_kg": 0.001, "stiffness_N_per_m": { "structural": 40, "shear": 20, "bend": 10 },
                   "damping_Ns_per_m": 0.05, "gravity_m_per_s2": [0, 0, 0], "fix_floor": true },
      "interaction": { "mode": "cut", "blade_length_m": 0.1, "cut_resistance_Ns_per_m": 2 },
      "trajectory": [
        { "t_s": 0.0, "pos_m": [-0.05, 0.004, 0.4] },
        { "t_s": 0.15, "pos_m": [-0.05, 0.004, 0.022], "button": B },
        { "t_s": 0.55, "pos_m": [0.05, 0.004, 0.022], "button": B },
        { "t_s": 0.6, "pos_m": [0.05, 0.004, 0.022] },
        { "t_s": 0.75, "pos_m": [0.05, 0.004, 0.4] }
      ],
      "render": { "width": 160, "height": 120, "style": "solid" },
      "duration_s": 0.9
    })";
    for (std::size_t at = t.find(": B"); at != std::string::npos; at = t.find(": B")) t.replace(at + 2, 1, button ? "true" : "false");
    return parse_scene(t, "slit.json").value();
  };
  auto last_frame = [](const std::string& dir) {
    std::vector<fs::path> frames;
    for (const auto& e : fs::directory_iterator(fs::path(dir) / "frames")) frames.push_back(e.path());
    std::sort(frames.begin(), frames.end());
    EXPECT_FALSE(frames.empty());
    return read_png(frames.back().string()).value();
  };
  const RecordResult cut = record(slit_scene(true), "slit_cut", true);
  const RecordResult none = record(slit_scene(false), "slit_none", true);
  const auto j = nlohmann::json::parse(cut.summary_json);
  ASSERT_GT(j["cut"]["triangles_added"].get<int>(), 0);
  EXPECT_EQ(j["cut"]["free_nodes"].get<int>(), 0);  // a slit: nothing comes free
  const Image a = last_frame(std::string(test::temp_root()) + "/slit_cut"), b = last_frame(std::string(test::temp_root()) + "/slit_none");
  ASSERT_EQ(a.rgba.size(), b.rgba.size());
  // pixels that differ, and the columns they span: the groove runs across the top along x
  int differ = 0, lo_col = a.width, hi_col = -1;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * a.width + x) * 4;
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(a.rgba[i + c] - b.rgba[i + c]));
      if (d <= 8) continue;
      ++differ;
      lo_col = std::min(lo_col, x);
      hi_col = std::max(hi_col, x);
    }
  RecordProperty("pixels_differ", differ);
  RecordProperty("columns_spanned", hi_col - lo_col + 1);
  EXPECT_GE(differ, 60) << "the slit is not seen";
  EXPECT_GE(hi_col - lo_col, a.width / 4) << "the differences do not follow the blade's path";
}

}  // namespace
}  // namespace palpate
