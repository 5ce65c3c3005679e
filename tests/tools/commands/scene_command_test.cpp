// `palpate scene`: generated scenes touch the model they were made for, at the point asked for.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/mesh_io.h"
#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/json_file.h"
#include "support/obj_text.h"
#include "support/read_file.h"
#include "tools/commands/scene_command.h"
#include "runtime/session/model.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

using test::CliRun;
using test::palpate;
using test::read_json;
using test::write_text;

// A 4 x 2 x 1 box (raw units) centred at (10, 0, 0), as an OBJ; normalised to 100 x 50 x 25 mm at the origin.
std::string box_obj(const std::string& dir) {
  fs::create_directories(dir);
  const std::string path = (fs::path(dir) / "box.obj").string();
  write_text(path, test::obj_text(make_box_mesh(Vec3(4.0, 2.0, 1.0), 2), Vec3(10.0, 0.0, 0.0)));
  return path;
}

// Writes a scene for `model` with `args`, records it for duration_s without frames, returns summary.json.
nlohmann::json scene_then_record(const std::string& model, const std::string& name, const std::string& args,
                                 double duration_s) {
  const std::string dir = test::fresh_dir("scene_" + name);
  fs::create_directories(dir);
  const std::string scene = dir + "/scene.json";
  const CliRun s = palpate("scene '" + model + "' " + args + " --out " + scene);
  EXPECT_EQ(s.code, 0) << s.out;
  EXPECT_NE(s.out.find("up axis"), std::string::npos) << s.out;
  const CliRun r = palpate("record " + scene + " --no-render -q --duration " + std::to_string(duration_s) + " -o " + dir + "/out");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("no contact"), std::string::npos) << name << ": " << r.out;
  return read_json(dir + "/out/summary.json");
}

TEST(SceneCommand, TouchScenesMakeContactOnTheBunnyAndAssimpTestModels) {
  std::vector<std::string> models{test::source_path("scenes/bunny.obj")};
  const fs::path assimp = "/usr/share/assimp/models";
  for (const char* m : {"OBJ/spider.obj", "PLY/Wuson.ply", "STL/sphereWithHole.stl", "Collada/teapots.DAE"})
    if (fs::exists(assimp / m)) models.push_back((assimp / m).string());
  if (models.size() < 5) std::fprintf(stderr, "assimp-testmodels missing: only the bunny is checked\n");
  for (std::size_t i = 0; i < models.size(); ++i) {
    SCOPED_TRACE(models[i]);
    const auto j = scene_then_record(models[i], "touch" + std::to_string(i), "--mode touch", 2.0);
    EXPECT_GT(j["max_force_N"].get<double>(), 0.0);
    EXPECT_GT(j["sim"]["nodes"].get<int>(), 0);
    EXPECT_EQ(j["nan_events"].get<int>(), 0);
    EXPECT_EQ(j["mode"], "lockstep");
  }
}

// docs/using.md's own-model walkthrough shows what `palpate scene` says for its model, line for line (it showed the
// bunny's lines for the Wuson once), and names the folder the recording is written to.
TEST(SceneCommand, TheOwnModelWalkthroughShowsWhatTheCommandSaysForItsModel) {
  const std::string wuson = "/usr/share/assimp/models/PLY/Wuson.ply";
  if (!fs::exists(wuson)) GTEST_SKIP() << "assimp-testmodels missing (scripts/install_deps.sh installs it)";
  const std::string doc = test::read_file(test::source_path("docs/using.md"));
  ASSERT_NE(doc.find("palpate scene " + wuson + " --mode touch --out out/wuson_touch.json"), std::string::npos);
  const std::string dir = test::fresh_dir("scene_walkthrough");
  fs::create_directories(dir);
  const CliRun r = palpate("scene " + wuson + " --mode touch --out " + dir + "/wuson_touch.json");
  ASSERT_EQ(r.code, 0) << r.out;
  int lines = 0;
  std::istringstream said(r.out);
  for (std::string line; std::getline(said, line);) {
    if (line.rfind("palpate scene: ", 0) != 0) continue;
    ++lines;
    EXPECT_NE(doc.find("\n" + line + "\n"), std::string::npos) << "docs/using.md does not show: " << line;
  }
  EXPECT_EQ(lines, 3) << r.out;
  // the recording's folder is the scene's name
  const std::string name = read_json(dir + "/wuson_touch.json")["name"].get<std::string>();
  EXPECT_NE(doc.find("out/" + name + "/frames/"), std::string::npos) << name;
}

TEST(SceneCommand, PullAndCutScenesMakeContactOnTheBunny) {
  const std::string bunny = test::source_path("scenes/bunny.obj");
  const auto pull = scene_then_record(bunny, "pull", "--mode pull", 1.6);
  EXPECT_GT(pull["max_force_N"].get<double>(), 0.0);
  EXPECT_GT(pull["max_displacement_m"].get<double>(), 1e-3);  // the grabbed surface follows the tool out
  // the blade goes in until 1.0 s and severs springs once it is drawn across
  const auto cut = scene_then_record(bunny, "cut", "--mode cut", 1.5);
  EXPECT_GT(cut["cut"]["springs_cut"].get<int>(), 0);
  EXPECT_EQ(cut["nan_events"].get<int>(), 0);
}

// A material the user names (E, nu, density) and a sphere with the contact solved: the scene carries them, the
// touch runs on the volume term at the asked nu, the contact is solved, and the press stays where it is pressed
// (the bunny's ear over the tool is not drawn onto it). Out-of-range numbers are refused naming the option.
TEST(SceneCommand, ATissueTheUserNamesIsTouchedWithTheContactSolved) {
  const std::string bunny = test::source_path("scenes/bunny.obj");
  const auto j = scene_then_record(bunny, "tissue", "--young-modulus 2e4 --poisson 0.45 --density 1050 --tool sphere "
                                   "--tool-radius-mm 6 --contact solved", 2.2);
  EXPECT_EQ(j["material"]["model"], "volumetric");
  EXPECT_EQ(j["material"]["poisson_ratio_represented"].get<double>(), 0.45);
  EXPECT_EQ(j["material"]["contact_model_error"]["contact"], "solved");
  EXPECT_GT(j["contact_load"]["solved_frames"].get<int>(), 50) << j["contact_load"].dump();
  EXPECT_GT(j["max_force_N"].get<double>(), 0.3);
  // a 10 mm press of a 6 mm sphere: the lattice moves millimetres, not centimetres
  EXPECT_LT(j["max_displacement_m"].get<double>(), 0.008);
  const std::string dir = test::fresh_dir("scene_tissue_bad");
  for (const std::string& bad : {std::string("--young-modulus 0.5"), std::string("--young-modulus 1e4 --poisson 0.5"),
                                 std::string("--poisson 0.3"), std::string("--mode pull --contact solved")}) {
    const CliRun r = palpate("scene " + bunny + " " + bad + " --out " + dir + "/s.json");
    EXPECT_NE(r.code, 0) << bad;
    EXPECT_FALSE(fs::exists(dir + "/s.json")) << bad;
  }
  const CliRun pull = palpate("scene " + bunny + " --mode pull --contact solved --out " + dir + "/s.json");
  EXPECT_NE(pull.out.find("--contact solved: the contact is solved under a pressing tool; --mode is 'pull'"),
            std::string::npos) << pull.out;
  // the sphere in pull or cut: refused up front, as `record` would refuse the scene, and nothing written
  for (const std::string mode : {"pull", "cut"}) {
    const CliRun sphere = palpate("scene " + bunny + " --mode " + mode + " --tool sphere --out " + dir + "/s.json");
    EXPECT_EQ(sphere.code, 1) << sphere.out;
    EXPECT_NE(sphere.out.find("--tool sphere: the sphere is a touch tool; --mode is '" + mode + "'"), std::string::npos)
        << sphere.out;
    EXPECT_FALSE(fs::exists(dir + "/s.json")) << mode;
  }
}

TEST(SceneCommand, FromPicksTheFirstSurfaceOnThatSideAndDepthSetsThePress) {
  const std::string obj = box_obj(test::fresh_dir("scene_from"));
  SceneRequest rq;
  rq.mesh_path = obj;
  rq.up_axis = 'z';
  rq.from = Vec3(1, 0, 0);
  rq.depth_mm = 4.0;
  auto g = generate_scene(rq);
  ASSERT_TRUE(g) << g.error().message;
  // the +x face of the normalised box (100 x 50 x 25 mm) through its centre, approached along -x
  EXPECT_NEAR(g.value().surface_point_m.x(), 0.05, 1e-9);
  // near the face's centre, inside a triangle and off the edges the triangles share (the face is 50 x 25 mm)
  EXPECT_NEAR(g.value().surface_point_m.y(), 0.0, 0.006);
  EXPECT_NEAR(g.value().surface_point_m.z(), 0.0, 0.006);
  EXPECT_TRUE(g.value().approach.isApprox(Vec3(-1, 0, 0)));
  const auto& t = g.value().json["trajectory"];
  EXPECT_NEAR(t.front()["pos_m"][0].get<double>(), 0.08, 1e-6);  // starts 30 mm out
  double deepest_x = 1.0;
  for (const auto& k : t) deepest_x = std::min(deepest_x, k["pos_m"][0].get<double>());
  EXPECT_NEAR(deepest_x, 0.046, 1e-6);  // presses 4 mm in

  rq.from = Vec3(0, -1, 0);
  g = generate_scene(rq);
  ASSERT_TRUE(g) << g.error().message;
  EXPECT_NEAR(g.value().surface_point_m.y(), -0.025, 1e-9);

  // default: from above
  rq.from.reset();
  g = generate_scene(rq);
  ASSERT_TRUE(g) << g.error().message;
  EXPECT_NEAR(g.value().surface_point_m.z(), 0.0125, 1e-9);
  EXPECT_TRUE(g.value().approach.isApprox(Vec3(0, 0, -1)));
  EXPECT_FALSE(g.value().json["render"].contains("view_from"));  // touch: the default view

  // a cut is seen from the side the blade comes in (the fixed view saw a flat part's top edge-on)
  rq.mode = InteractionMode::kCut;
  for (const Vec3& from : {Vec3(0, 0, 1), Vec3(1, 0, 0)}) {
    rq.from = from;
    g = generate_scene(rq);
    ASSERT_TRUE(g) << g.error().message;
    const auto& v = g.value().json["render"]["view_from"];
    const Vec3 view(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
    EXPECT_GT(view.normalized().dot(-g.value().approach), 0.8) << from.transpose();
  }
}

TEST(SceneCommand, AtPicksTheNearestSurfacePointInTheFilesCoordinates) {
  const std::string obj = box_obj(test::fresh_dir("scene_at"));
  SceneRequest rq;
  rq.mesh_path = obj;
  rq.up_axis = 'z';
  rq.at_raw = Vec3(11.0, 0.5, 3.0);  // above the box (top at raw z = 0.5), off centre
  auto g = generate_scene(rq);
  ASSERT_TRUE(g) << g.error().message;
  // raw (11, 0.5, 0.5) on the top face -> world ((11 - 10) * 25 mm, 0.5 * 25 mm, 12.5 mm)
  EXPECT_NEAR(g.value().surface_point_m.x(), 0.025, 1e-9);
  EXPECT_NEAR(g.value().surface_point_m.y(), 0.0125, 1e-9);
  EXPECT_NEAR(g.value().surface_point_m.z(), 0.0125, 1e-9);
  EXPECT_TRUE(g.value().approach.isApprox(Vec3(0, 0, -1), 1e-9));

  // the same from the command line, with a y-up file: the file's +y face is the world's top; the mesh path is
  // relative when the scene sits above the mesh, absolute otherwise, and resolves either way
  const fs::path mesh_dir = fs::path(obj).parent_path();
  const std::string other = test::fresh_dir("scene_at_cli");
  fs::create_directories(other);
  for (const auto& [scene, file] : {std::pair{mesh_dir.parent_path() / "s.json", std::string("scene_at/box.obj")},
                                    std::pair{fs::path(other) / "s.json", obj}}) {
    const CliRun r = palpate("scene " + obj + " --up y --at 9,5,0 --out " + scene.string());
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_NE(r.out.find("up axis y (--up)"), std::string::npos) << r.out;
    const auto j = read_json(scene.string());
    EXPECT_EQ(j["mesh"]["file"].get<std::string>(), file);
    EXPECT_EQ(j["mesh"]["up_axis"], "y");
    auto loaded = load_scene(scene.string());
    ASSERT_TRUE(loaded) << loaded.error().message;
    ASSERT_TRUE(load_model(loaded.value())) << "the mesh path resolves";
    // raw (9, 1, 0) on the +y face -> world (-25, 0, 25) mm after the y-up rotation (raw y spans 2 units = 50 mm)
    const auto& press = j["trajectory"][3]["pos_m"];
    EXPECT_NEAR(press[0].get<double>(), -0.025, 1e-6);
    EXPECT_NEAR(press[1].get<double>(), 0.0, 1e-6);
    EXPECT_NEAR(press[2].get<double>(), 0.025 - 0.010, 1e-6);  // 10 mm in
  }
}

TEST(SceneCommand, BadOptionsAndOutputsAreRefusedNamingThem) {
  const std::string dir = test::fresh_dir("scene_bad");
  fs::create_directories(dir + "/a_folder");
  const std::string bunny = test::source_path("scenes/bunny.obj");
  CliRun r = palpate("scene " + bunny + " --from up");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--from 'up': expected an axis"), std::string::npos) << r.out;
  r = palpate("scene " + bunny + " --at 1,2");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--at '1,2': expected three numbers"), std::string::npos) << r.out;
  r = palpate("scene " + bunny + " --out " + dir + "/a_folder");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("is not a regular file"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::is_directory(dir + "/a_folder"));
  r = palpate("scene " + dir + "/missing.obj");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("missing.obj"), std::string::npos) << r.out;
  // an existing scene file is replaced, and nothing temporary is left beside it
  write_text(dir + "/s.json", "old");
  r = palpate("scene " + bunny + " --out " + dir + "/s.json");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(load_scene(dir + "/s.json")) << "the file was replaced by a loadable scene";
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  // a folder that is not there yet is made (the README's `--out out/x.json` in a fresh clone); one that cannot be
  // made (under a regular file) is named
  r = palpate("scene " + bunny + " --out " + dir + "/new/deeper/s.json");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(load_scene(dir + "/new/deeper/s.json")) << r.out;
  r = palpate("scene " + bunny + " --out " + dir + "/s.json/under/x.json");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("cannot make its folder '" + dir + "/s.json/under'"), std::string::npos) << r.out;
}

TEST(SceneCommand, TheScenesNameIsOneTheReaderTakesAndTheMeshIsNeverOverwritten) {
  const std::string dir = test::fresh_dir("scene_names");
  fs::create_directories(dir);
  const std::string box = box_obj(dir);
  // a file name of characters a scene name may not hold, and a long one
  const std::string odd = dir + "/poly2x^2+y^2-0.062500.obj";
  const std::string long_name = dir + "/" + std::string(80, 'm') + ".obj";
  for (const std::string& copy : {odd, long_name}) {
    fs::copy_file(box, copy, fs::copy_options::overwrite_existing);
    const std::string scene = dir + "/named.json";
    const CliRun r = palpate("scene '" + copy + "' --mode cut --out " + scene);
    ASSERT_EQ(r.code, 0) << r.out;
    const auto j = read_json(scene);
    const std::string name = j["name"].get<std::string>();
    EXPECT_LE(name.size(), 64u) << name;
    EXPECT_EQ(name.substr(name.size() - 4), "_cut") << name;
    auto loaded = load_scene(scene);
    ASSERT_TRUE(loaded) << loaded.error().message;
  }
  EXPECT_EQ(read_json(dir + "/named.json")["name"], std::string(60, 'm') + "_cut");
  const CliRun odd_run = palpate("scene '" + odd + "' --out " + dir + "/odd.json");
  ASSERT_EQ(odd_run.code, 0) << odd_run.out;
  EXPECT_EQ(read_json(dir + "/odd.json")["name"], "poly2x_2_y_2-0.062500_touch");

  // --out naming the mesh itself (or a link to it) is refused and the mesh kept
  const std::string before = test::read_file(box);
  for (const std::string& out : {box, dir + "/../" + fs::path(dir).filename().string() + "/box.obj"}) {
    const CliRun r = palpate("scene " + box + " --out " + out);
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("is the mesh file itself"), std::string::npos) << r.out;
  }
  fs::create_symlink(box, dir + "/link.obj");
  EXPECT_EQ(palpate("scene " + box + " --out " + dir + "/link.obj").code, 1);
  EXPECT_EQ(test::read_file(box), before);
}

TEST(SceneCommand, NumbersThatAreNotFiniteAreRefused) {
  const std::string bunny = test::source_path("scenes/bunny.obj");
  const std::string dir = test::fresh_dir("scene_nan");
  fs::create_directories(dir);
  for (const char* bad : {"nan", "-nan", "inf", "1e999", "0.1"}) {
    const CliRun r = palpate("scene " + bunny + " --depth-mm " + bad + " --out " + dir + "/s.json");
    EXPECT_NE(r.code, 0) << bad << ": " << r.out;
    EXPECT_NE(r.out.find("--depth-mm"), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(dir + "/s.json")) << bad;
  }
  SceneRequest rq;
  rq.mesh_path = bunny;
  rq.depth_mm = std::nan("");
  ASSERT_FALSE(generate_scene(rq));
  EXPECT_NE(generate_scene(rq).error().message.find("--depth-mm nan: not a number in [0.5, 50]"), std::string::npos);
  rq.depth_mm = 0.0;
  rq.at_raw = Vec3(0, std::numeric_limits<double>::infinity(), 0);
  EXPECT_FALSE(generate_scene(rq));
}

// A flat CAD plate 100 x 5 x 60 lying on its edge in the file: the up axis is its thin one, so the tool comes down
// on its 100 x 60 face, not on its 5 mm rim (the wrong axis passes a contact test but touches the rim)
TEST(SceneCommand, AFlatPlateIsTouchedOnItsFace) {
  const std::string dir = test::fresh_dir("plate_model");
  fs::create_directories(dir);
  const std::string path = dir + "/plate.obj";
  write_text(path, test::obj_text(make_box_mesh(Vec3(100.0, 5.0, 60.0), 4)));
  {
    SceneRequest rq;
    rq.mesh_path = path;
    auto g = generate_scene(rq);
    ASSERT_TRUE(g) << g.error().message;
    EXPECT_EQ(g.value().json["mesh"]["up_axis"], "y");
    // normalised: 100 mm along x, the 5 mm thickness along world z, 60 mm along world y
    EXPECT_NEAR(g.value().surface_point_m.z(), 0.0025, 1e-6);
    EXPECT_TRUE(g.value().approach.isApprox(Vec3(0, 0, -1), 1e-9));
    // the face under the tool is the plate's broad face: its neighbourhood spans far more than the rim's 5 mm
    EXPECT_LT(std::abs(g.value().surface_point_m.x()), 0.04);
    EXPECT_LT(std::abs(g.value().surface_point_m.y()), 0.025);
  }
  // and the record presses into it
  const auto j = scene_then_record(dir + "/plate.obj", "plate", "--mode touch", 2.0);
  EXPECT_GT(j["max_force_N"].get<double>(), 0.0);
}

// A cube of 8 vertices and 6 quads (assimp's cube.ply): each face splits along a diagonal through its centre, so
// a tool coming down through the centre moves along the edge the two triangles share; the scene's point is taken
// inside a triangle and every mode meets the surface (the cut used to cut springs without the blade ever touching)
TEST(SceneCommand, EveryModeMeetsACubeOfEightVertices) {
  const std::string dir = test::fresh_dir("scene_cube");
  fs::create_directories(dir);
  const std::string cube = dir + "/cube.ply";
  write_text(cube, "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
              "element face 6\nproperty list uchar int vertex_indices\nend_header\n"
              "0 0 0\n0 0 1\n0 1 1\n0 1 0\n1 0 0\n1 0 1\n1 1 1\n1 1 0\n"
              "4 0 1 2 3\n4 7 6 5 4\n4 0 4 5 1\n4 1 5 6 2\n4 2 6 7 3\n4 3 7 4 0\n");
  SceneRequest rq;
  rq.mesh_path = cube;
  auto g = generate_scene(rq);
  ASSERT_TRUE(g) << g.error().message;
  // on the top face, off its centre (where a diagonal runs)
  EXPECT_NEAR(g.value().surface_point_m.z(), 0.05, 1e-9);
  EXPECT_GT(g.value().surface_point_m.head<2>().norm(), 1e-3);
  for (const char* mode : {"touch", "pull", "cut"}) {
    SCOPED_TRACE(mode);
    const auto j = scene_then_record(cube, std::string("cube_") + mode, std::string("--mode ") + mode, 2.4);
    EXPECT_GT(j["max_force_N"].get<double>(), 0.0);
    EXPECT_EQ(j["nan_events"].get<int>(), 0);
    if (std::string(mode) == "cut") {
      EXPECT_GT(j["cut"]["springs_cut"].get<int>(), 0);
      // subdivided (below), the stroke across the top splits a row of triangles to draw its groove (12 triangles of
      // 100 mm: the blade split 2, at the edge it left through, and its path showed nothing)
      EXPECT_GE(j["cut"]["triangles_added"].get<int>(), 16);
    }
  }
  // a cut scene subdivides the cube until its longest edge (the faces' 141 mm diagonals) is two 6.25 mm cells or
  // less: 141 / 2^4 = 8.8 mm, 12 x 4^4 triangles; a touch scene leaves it as it is
  SceneRequest cut = rq;
  cut.mode = InteractionMode::kCut;
  auto gc = generate_scene(cut);
  ASSERT_TRUE(gc) << gc.error().message;
  EXPECT_EQ(gc.value().json["mesh"]["subdivisions"], 4);
  EXPECT_FALSE(g.value().json["mesh"].contains("subdivisions"));
}

}  // namespace
}  // namespace palpate
