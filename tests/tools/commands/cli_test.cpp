// The palpate command as a user runs it: exit codes and one-line errors naming the culprit.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include <nlohmann/json.hpp>

#include "sim/contact/contact_model_error.h"
#include "support/cli_run.h"
#include "support/temp_root.h"
#include "support/fixtures.h"
#include "support/json_file.h"
#include "support/read_file.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

using test::CliRun;
using test::palpate;
using test::read_file;
using test::write_text;

std::string tmp(const std::string& name) { return test::temp_path("palpate_cli_", name); }

// A scene using the given mesh file, written next to it.
std::string scene_for_mesh(const std::string& mesh, const std::string& name) {
  const std::string s = tmp(name + ".json");
  write_text(s, R"({"mesh": {"file": ")" + mesh + R"("}, "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.1]}], "duration_s": 0.1})");
  return s;
}

void expect_error(const CliRun& r, const std::string& needle) {
  EXPECT_TRUE(r.code == 1 || r.code == 2) << "exit " << r.code << ": " << r.out;
  EXPECT_NE(r.out.find(needle), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one line expected: " << r.out;
}

TEST(Cli, HelpListsCommands) {
  const CliRun r = palpate("--help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("record"), std::string::npos);
  EXPECT_NE(r.out.find("info"), std::string::npos);
}

TEST(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(palpate("").code, 2);
  EXPECT_EQ(palpate("record").code, 2);
  EXPECT_EQ(palpate("record x.json --mode fast").code, 2);
}

// Usage errors look like every other error: the program's name first, then where to look.
TEST(Cli, UsageErrorsNameTheProgram) {
  for (const char* args : {"record", "record --bogus x", "bench sim scenes/bunny_pull.json --levels abc", "nosuchcommand"}) {
    const CliRun r = palpate(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.out.rfind("palpate: ", 0), 0u) << args << ": " << r.out;
    EXPECT_NE(r.out.find("--help"), std::string::npos) << args << ": " << r.out;
  }
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  const CliRun d = test::shell(std::string(bin ? bin : "build/bin") + "/palpate-device --bogus");
  EXPECT_EQ(d.code, 2);
  EXPECT_EQ(d.out.rfind("palpate-device: ", 0), 0u) << d.out;
}

TEST(Cli, InfoReportsTheBunnyAndItsLevels) {
  const CliRun r = palpate("info scenes/bunny.obj --levels 4 --json");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("\"vertices\": 1839"), std::string::npos);
  EXPECT_NE(r.out.find("\"triangles\": 3674"), std::string::npos);
  EXPECT_NE(r.out.find("\"level\": 4"), std::string::npos);
}

TEST(Cli, MissingMeshNamesTheFile) {
  const std::string out = tmp("out_missing");
  fs::remove_all(out);
  expect_error(palpate("record " + scene_for_mesh("/nonexistent/m.obj", "missing") + " --out " + out + " -q"),
               "mesh '/nonexistent/m.obj': file not found");
  EXPECT_FALSE(fs::exists(out));  // nothing written for a bad input
}

TEST(Cli, EmptyMalformedAndNonMeshFiles) {
  const std::string empty = tmp("empty.obj"), bad = tmp("bad.obj"), png = tmp("picture.stl");
  write_text(empty, "");
  write_text(bad, "v 1 2\nf 1 2 9 x\nthis is not obj\n");
  write_text(png, std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR garbage", 24));
  expect_error(palpate("info " + empty), "mesh '" + empty + "': file is empty");
  for (const auto& f : {bad, png}) {
    const CliRun r = palpate("info " + f);
    expect_error(r, "mesh '" + f + "'");
  }
}

TEST(Cli, FlatMeshIsRejected) {
  const std::string flat = tmp("flat.obj");
  write_text(flat, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n");
  expect_error(palpate("info " + flat), "flat on axis z");
  expect_error(palpate("record " + scene_for_mesh(flat, "flat") + " -q --out " + tmp("out_flat")), "flat on axis z");
}

TEST(Cli, SceneWithWrongKeyNamesTheKey) {
  const std::string s = tmp("wrongkey.json");
  write_text(s, R"({"mesh": {"box_m": [0.05, 0.05, 0.05]}, "lattice": {"stifness": 3}, "trajectory": [{"t_s": 0, "pos_m": [0,0,0]}]})");
  expect_error(palpate("record " + s + " -q"), "lattice.stifness: unknown key");
}

TEST(Cli, UnwritableOutputFolderIsAnError) {
  const std::string file = tmp("a_file");
  write_text(file, "x");
  expect_error(palpate("record scenes/cube_press.json -q --duration 0.1 --out " + file + "/sub"),
               "output '" + file + "/sub': cannot create folder");
}

// cube_press in physical units: summary.json says what the material became (nu represented, total mass), and a
// Poisson ratio the lattice cannot represent is said at start-up, not hidden.
TEST(Cli, MaterialIsReportedAtStartAndInTheSummary) {
  const std::string out = tmp("material_out");
  // 0.3 s: the tool reaches the cube (a recording that never touches warns "no contact in ...")
  const CliRun r = palpate("record scenes/cube_press.json -q --no-render --duration 0.3 --out " + out);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(r.out.find("warning"), std::string::npos) << r.out;
  // the end of the run says it too, in a line
  EXPECT_NE(r.out.find("material springs, E 200000 Pa, nu 0.25 (lattice 0.25), 1070 kg/m^3, 7.5 mm cells; contact "
                       "prescribed: a point load, no Hertz figure"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(read_file(out + "/summary.json"));
  ASSERT_TRUE(j.contains("material")) << j.dump();
  EXPECT_EQ(j["material"]["poisson_ratio_represented"].get<double>(), 0.25);
  EXPECT_NEAR(j["material"]["total_mass_kg"].get<double>(), 1070.0 * 0.06 * 0.06 * 0.06, 1e-9);
  EXPECT_TRUE(j.contains("state_hash"));
  // the tool pressing the cube is never free inside it
  EXPECT_EQ(j["tool_inside"]["frames"].get<int64_t>(), 0) << j["tool_inside"].dump();
  // its point tool: no Hertz figure, and the summary says why
  EXPECT_TRUE(j["material"]["contact_model_error"]["hertz_force_error"].is_null()) << j["material"].dump();
  EXPECT_NE(j["material"]["contact_model_error"]["basis"].get<std::string>().find("point tool"), std::string::npos);

  nlohmann::json scene = nlohmann::json::parse(read_file(test::source_path("scenes/cube_press.json")));
  scene["material"]["poisson_ratio"] = 0.45;
  scene["device"]["tool_shape"] = "sphere";
  const std::string s = tmp("nu045.json");
  write_text(s, scene.dump());
  const CliRun w = palpate("record " + s + " -q --no-render --duration 0.1 --out " + tmp("nu045_out"));
  ASSERT_EQ(w.code, 0) << w.out;
  EXPECT_NE(w.out.find("warning: material.poisson_ratio 0.45 is not representable"), std::string::npos) << w.out;
  const auto k = nlohmann::json::parse(read_file(tmp("nu045_out") + "/summary.json"));
  EXPECT_EQ(k["material"]["poisson_ratio_asked"].get<double>(), 0.45);
  EXPECT_EQ(k["material"]["poisson_ratio_represented"].get<double>(), 0.25);
  // a 2 mm sphere on 7.5 mm cells (level 4 of the 6 cm cube): the springs' calibration at 0.27 cells
  const auto& c = k["material"]["contact_model_error"];
  EXPECT_NEAR(c["contact_radius_cells"].get<double>(), 0.002 / 0.0075, 1e-9) << c.dump();
  EXPECT_DOUBLE_EQ(c["hertz_force_error"].get<double>(),
                   contact_model_error(MaterialSpec{}, true, 0.002, 0.0075).hertz_force_error);
  EXPECT_NE(c["source"].get<std::string>().find("palpate bench model"), std::string::npos);
  char line[120];
  std::snprintf(line, sizeof line, "contact prescribed: force %+.0f %% against Hertz at 0.27 cells",
                100.0 * c["hertz_force_error"].get<double>());
  EXPECT_NE(w.out.find(line), std::string::npos) << line << " in " << w.out;
}

// A body too soft to carry its own weight is said before the run, its height the model's extent along gravity: a
// 6 x 6 x 0.6 cm plate of E 1260 Pa lying flat takes 5 % at its foot (nothing said), stood on its edge by gravity
// along x 50 % (said, with that height).
TEST(Cli, ABodyTooSoftForItsOwnWeightIsSaidWithItsHeightAlongGravity) {
  nlohmann::json scene = nlohmann::json::parse(read_file(test::source_path("scenes/cube_press.json")));
  scene["mesh"]["box_m"] = {0.06, 0.06, 0.006};
  scene["material"]["young_modulus_Pa"] = 1260.0;
  const std::string flat = tmp("soft_flat.json");
  write_text(flat, scene.dump());
  const CliRun lying = palpate("record " + flat + " -q --no-render --duration 0.05 --out " + tmp("soft_flat_out"));
  ASSERT_EQ(lying.code, 0) << lying.out;
  EXPECT_EQ(lying.out.find("own weight"), std::string::npos) << lying.out;
  scene["lattice"]["gravity_m_per_s2"] = {-9.81, 0.0, 0.0};
  const std::string edge = tmp("soft_edge.json");
  write_text(edge, scene.dump());
  const CliRun standing = palpate("record " + edge + " -q --no-render --duration 0.05 --out " + tmp("soft_edge_out"));
  ASSERT_EQ(standing.code, 0) << standing.out;
  EXPECT_NE(standing.out.find("warning: material: under its own weight"), std::string::npos) << standing.out;
  EXPECT_NE(standing.out.find("the 0.06 m tall box takes a strain rho g H / E = 50"), std::string::npos) << standing.out;
}

// A lattice finer than the mesh's triangles is said before the run: cube_press's 5 mm quads (longest edge 7.1 mm)
// under level-6 cells of 1.875 mm, and not once the faces are cut in 2.5 mm quads (3.5 mm) or the lattice is level 4.
TEST(Cli, ALatticeFinerThanTheMeshsTrianglesIsSaid) {
  nlohmann::json scene = nlohmann::json::parse(read_file(test::source_path("scenes/cube_press.json")));
  scene["lattice"]["level"] = 6;
  scene["grid"]["levels"] = 6;
  const auto run = [&](const char* name) {
    const std::string path = tmp(std::string(name) + ".json");
    write_text(path, scene.dump());
    const CliRun r = palpate("record " + path + " -q --no-render --duration 0.05 --out " + tmp(std::string(name) + "_out"));
    EXPECT_EQ(r.code, 0) << r.out;
    return r.out;
  };
  const std::string coarse = run("coarse_mesh");
  EXPECT_NE(coarse.find("warning: mesh: its triangles (median longest edge 7.07 mm) are coarser than the lattice's "
                        "finest cells (1.88 mm at level 6)"),
            std::string::npos)
      << coarse;
  scene["mesh"]["box_subdivisions"] = 24;
  EXPECT_EQ(run("fine_mesh").find("coarser than"), std::string::npos);
  scene["mesh"]["box_subdivisions"] = 12;
  scene["lattice"]["level"] = 4;
  EXPECT_EQ(run("coarse_lattice").find("coarser than"), std::string::npos);
}

// summary.json's sim.max_strain: the largest spring strain of the run. cube_press as shipped (200 kPa) stays within
// the springs' calibrated 10 % (4.4 %); at 10 kPa the same press strains the springs under the point 95 %.
TEST(Cli, TheRunsLargestSpringStrainIsInTheSummary) {
  nlohmann::json scene = nlohmann::json::parse(read_file(test::source_path("scenes/cube_press.json")));
  const auto strain = [&](const char* name) {
    const std::string path = tmp(std::string(name) + ".json");
    write_text(path, scene.dump());
    const std::string out = tmp(std::string(name) + "_out");
    const CliRun r = palpate("record " + path + " -q --no-render --out " + out);
    EXPECT_EQ(r.code, 0) << r.out;
    return test::read_json(out + "/summary.json")["sim"]["max_strain"].get<double>();
  };
  const double stiff = strain("strain_stiff");
  EXPECT_GT(stiff, 0.01);
  EXPECT_LT(stiff, 0.1);
  scene["material"]["young_modulus_Pa"] = 1e4;
  EXPECT_GT(strain("strain_soft"), 0.5);
}

TEST(Cli, AssimpInvalidModelsGiveErrorsNotCrashes) {
  const fs::path dir = "/usr/share/assimp/models/invalid";
  if (!fs::exists(dir)) GTEST_SKIP() << "assimp-testmodels not installed";
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const CliRun r = palpate("info '" + e.path().string() + "'");
    EXPECT_TRUE(r.code == 1) << e.path() << " exit " << r.code << ": " << r.out;
    EXPECT_NE(r.out.find("mesh '"), std::string::npos) << r.out;
    ++n;
  }
  EXPECT_GT(n, 0);
}

TEST(Cli, BenchScaleRecordsEachSizeBothWaysAndWritesItsRows) {
  const std::string json = tmp("scale.json");
  const CliRun r = palpate("bench scale scenes/bunny_touch.json --max-subdivisions 1 --duration 1.0 -q --json " + json);
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream f(json);
  const auto j = nlohmann::json::parse(f);
  ASSERT_EQ(j["rows"].size(), 4u);  // 3674 and 14696 triangles, layered and full redraw
  for (const auto& row : j["rows"]) {
    const bool full = row["full_redraw"].get<bool>();
    const int64_t tris = row["triangles"].get<int64_t>();
    EXPECT_TRUE(tris == 3674 || tris == 14696) << tris;
    EXPECT_EQ(row["subdivisions"].get<int>(), tris == 3674 ? 0 : 1);
    EXPECT_GT(row["peak_rss_MB"].get<double>(), 10.0);
    EXPECT_EQ(row["render_ms"]["count"].get<int64_t>(), 60);
    // the cached layer is used in the layered runs only, and both draw the same recording
    EXPECT_EQ(row["frames_layered"].get<int64_t>(), full ? 0 : 60);
    // bunny_touch is drawn `both`: each row says whether its wireframe was drawn (both sizes' edges are long)
    EXPECT_TRUE(row["wire"]["drawn"].get<bool>()) << tris;
    EXPECT_GT(row["wire"]["median_edge_px"].get<double>(), 2.0) << tris;
    // edges this long are drawn as they are, not clustered
    EXPECT_FALSE(row["lod"]["used"].get<bool>()) << tris;
    EXPECT_EQ(row["lod"]["min_edge_px"].get<double>(), kLodMinEdgePxDefault);
  }
  EXPECT_EQ(j["rows"][0]["state_hash"], j["rows"][1]["state_hash"]);
  EXPECT_NE(j["rows"][0]["state_hash"], j["rows"][2]["state_hash"]);  // a finer mesh deforms other vertices
  // the table names every size, and whether its lines were drawn
  EXPECT_NE(r.out.find("14696"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("lines"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("drawn"), std::string::npos) << r.out;
}

TEST(Cli, BenchScaleRefusesAnOutputThatIsNotAFile) {
  expect_error(palpate("bench scale --max-subdivisions 0 --duration 0.1 -q --json /dev/null"), "/dev/null");
}

TEST(Cli, BenchPngComparesEncodersOnARecordingsFramesAndChecksThemLossless) {
  const std::string rec = tmp("png_rec");
  fs::remove_all(rec);
  const CliRun made = palpate("record scenes/cube_press.json --duration 0.2 -q --no-video --out " + rec);
  ASSERT_EQ(made.code, 0) << made.out;
  const std::string json = tmp("png.json");
  const CliRun r = palpate("bench png " + rec + " --frames 6 --reps 1 --json " + json);
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream f(json);
  const auto j = nlohmann::json::parse(f);
  EXPECT_EQ(j["frames"].get<int>(), 6);
  // zlib RGBA and RGB, libdeflate L2 with each of the four filters, L1 with three, L4 with none
  ASSERT_EQ(j["rows"].size(), 10u);
  int used = -1;
  for (std::size_t i = 0; i < j["rows"].size(); ++i) {
    const auto& row = j["rows"][i];
    EXPECT_TRUE(row["lossless"].get<bool>()) << row["encoder"];
    EXPECT_GT(row["cpu_p50_ms"].get<double>(), 0.0);
    if (row["encoder"].get<std::string>().find("(used)") != std::string::npos) used = static_cast<int>(i);
  }
  ASSERT_EQ(used, 8) << "libdeflate L1 RGB none is the encoder recordings use";
  // RGB and libdeflate (L2 SUB, and the one used) shrink the frames against the RGBA + zlib baseline (row 0)
  EXPECT_LT(j["rows"][1]["kB_per_frame"].get<double>(), j["rows"][0]["kB_per_frame"].get<double>());
  EXPECT_LT(j["rows"][2]["kB_per_frame"].get<double>(), j["rows"][1]["kB_per_frame"].get<double>());
  EXPECT_LT(j["rows"][8]["kB_per_frame"].get<double>(), j["rows"][1]["kB_per_frame"].get<double>());
  // no frames, or an output that is not a file: an error naming it, before any work
  const std::string empty = tmp("png_empty");
  fs::create_directories(empty);
  expect_error(palpate("bench png " + empty), "no frame_*.png in");
  expect_error(palpate("bench png " + rec + " --json /dev/null"), "/dev/null");
}

TEST(Cli, BenchSimNamesAnUnknownIntegratorOnBothPaths) {
  expect_error(palpate("bench sim scenes/bunny_pull.json --integrators verlet -q"), "unknown integrator 'verlet'");
  expect_error(palpate("bench sim scenes/bunny_pull.json --box 2 --integrators verlet -q"), "unknown integrator 'verlet'");
}

}  // namespace
}  // namespace palpate

namespace palpate {
namespace {

// What the system refuses the servo is said on stderr and kept in summary.json, memory locking included: run
// without the capability to lock memory and with no lockable memory (capsh and ulimit, as a user without
// privileges runs it).
TEST(Cli, RealtimeRefusalsIncludingMlockallReachTheSummary) {
  ASSERT_EQ(test::shell("command -v capsh").code, 0) << "capsh (Debian libcap2-bin) is needed by this test";
  const std::string out = tmp("out_refused");
  fs::remove_all(out);
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  const std::string cmd = "capsh --drop=cap_ipc_lock -- -c 'ulimit -l 0; exec " + std::string(bin ? bin : "build/bin") +
                          "/palpate record scenes/cube_press.json --mode realtime --duration 0.2 --no-render -q --out " +
                          out + "'";
  const CliRun r = test::shell(cmd);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("palpate: servo: refused: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mlockall"), std::string::npos) << r.out;
  const auto summary = nlohmann::json::parse(read_file(out + "/summary.json"));
  const std::string refused = summary["servo"]["rt"]["refused"].get<std::string>();
  EXPECT_NE(refused.find("mlockall: "), std::string::npos) << refused;
  EXPECT_FALSE(summary["servo"]["rt"]["memory_locked"].get<bool>()) << summary["servo"]["rt"].dump();
}

}  // namespace
}  // namespace palpate

namespace palpate {
namespace {

// The benchmarks' default scenes are found when the command runs from another folder than the repository root.
TEST(Cli, BenchDefaultScenesAreFoundFromAnyFolder) {
  const std::string elsewhere = tmp("elsewhere");
  fs::create_directories(elsewhere);
  const char* bin_env = std::getenv("PALPATE_BIN_DIR");
  const std::string bin = fs::absolute(bin_env ? bin_env : "build/bin").string();
  const CliRun scale = test::shell("cd " + elsewhere + " && " + bin +
                                   "/palpate bench scale --max-subdivisions 0 --duration 0.05 --no-full");
  EXPECT_EQ(scale.code, 0) << scale.out;
  EXPECT_NE(scale.out.find("bunny_pull"), std::string::npos) << scale.out;
  const CliRun loop = test::shell("cd " + elsewhere + " && " + bin + "/palpate bench loop --seconds 0.2 --load sim");
  EXPECT_EQ(loop.code, 0) << loop.out;
  // an explicit relative path stays relative to the current folder, as a user expects
  const CliRun named = test::shell("cd " + elsewhere + " && " + bin + "/palpate bench scale scenes/bunny_pull.json "
                                   "--max-subdivisions 0 --duration 0.05 --no-full");
  EXPECT_NE(named.code, 0) << named.out;
  EXPECT_NE(named.out.find("scenes/bunny_pull.json"), std::string::npos) << named.out;
}

// the feel of a recorded hand: bench feel replaying a recording's haptic.csv gives the figures of the run that wrote
// it (lockstep reproduces the state), over the log's whole length; a replay log that is not there is named
TEST(Cli, BenchFeelOfARecordedHandEqualsTheRunThatRecordedIt) {
  const std::string rec = tmp("feel_rec");
  const std::string scripted = tmp("feel_scripted.json"), replayed = tmp("feel_replayed.json");
  ASSERT_EQ(palpate("record scenes/cube_press.json --no-render -q -o " + rec).code, 0);
  const CliRun a = palpate("bench feel scenes/cube_press.json --json " + scripted);
  ASSERT_EQ(a.code, 0) << a.out;
  const CliRun b = palpate("bench feel scenes/cube_press.json --device replay:" + rec + " --json " + replayed);
  ASSERT_EQ(b.code, 0) << b.out;
  const auto ja = test::read_json(scripted), jb = test::read_json(replayed);
  EXPECT_GT(ja["scenes"][0]["contact_ticks"].get<int>(), 500);
  EXPECT_EQ(ja, jb);
  const CliRun missing = palpate("bench feel scenes/cube_press.json --device replay:" + tmp("no_such_recording"));
  EXPECT_NE(missing.code, 0);
  EXPECT_NE(missing.out.find("no_such_recording"), std::string::npos) << missing.out;
}

}  // namespace
}  // namespace palpate

namespace palpate {
namespace {

// A recording without rendering leaves no frames/ folder (and removes an earlier run's, emptied).
TEST(Cli, NoRenderLeavesNoFramesFolder) {
  const std::string out = tmp("out_norender");
  fs::remove_all(out);
  const CliRun drawn = palpate("record scenes/cube_press.json --duration 0.05 -q --no-video --out " + out);
  ASSERT_EQ(drawn.code, 0) << drawn.out;
  ASSERT_TRUE(fs::exists(out + "/frames/frame_00000.png"));
  const CliRun bare = palpate("record scenes/cube_press.json --duration 0.05 -q --no-render --out " + out);
  ASSERT_EQ(bare.code, 0) << bare.out;
  EXPECT_FALSE(fs::exists(out + "/frames")) << "frames/ left by a run that drew nothing";
  EXPECT_EQ(bare.out.find("frames/"), std::string::npos) << "a frames/ folder printed that does not exist: " << bare.out;
  EXPECT_NE(drawn.out.find("frames   " + out + "/frames/ (3 PNG)"), std::string::npos) << drawn.out;
  const auto summary = nlohmann::json::parse(read_file(out + "/summary.json"));
  EXPECT_TRUE(summary["outputs"]["frames"].is_null()) << summary["outputs"].dump();
  EXPECT_TRUE(fs::exists(out + "/haptic.csv"));
}

}  // namespace
}  // namespace palpate

namespace palpate {
namespace {

// `palpate scene` prints the record command as it can be pasted: the program as it was invoked, not a bare
// "palpate" that is not on PATH.
TEST(Cli, SceneCommandPrintsARecordCommandThatRunsAsPasted) {
  const std::string out = tmp("scene_paste");
  fs::create_directories(out);
  const std::string scene = out + "/s.json";
  const CliRun made = palpate("scene scenes/bunny.obj --out " + scene);
  ASSERT_EQ(made.code, 0) << made.out;
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  const std::string program = std::string(bin ? bin : "build/bin") + "/palpate";
  const std::string line = "record   " + program + " record " + scene;
  ASSERT_NE(made.out.find(line), std::string::npos) << made.out;
  // pasted as printed (with a short run and no outputs to speak of)
  const CliRun pasted = test::shell(program + " record " + scene + " --duration 0.05 -q --no-render --out " + out + "/rec");
  EXPECT_EQ(pasted.code, 0) << pasted.out;
}

// `bench scale --help` shows its flag plainly (no "{false}" default after it) and how long the benchmark takes.
TEST(Cli, BenchHelpSaysHowLongAndShowsNoStrayDefaults) {
  const CliRun scale = palpate("bench scale --help");
  EXPECT_NE(scale.out.find("--no-full"), std::string::npos) << scale.out;
  EXPECT_EQ(scale.out.find("{false}"), std::string::npos) << scale.out;
  EXPECT_NE(scale.out.find("about 1.6 min"), std::string::npos) << scale.out;
  EXPECT_NE(palpate("bench model --help").out.find("about 6 min"), std::string::npos);
  EXPECT_NE(palpate("bench png --help").out.find("about 47 s"), std::string::npos);
}

// The help's "none" for no rows parses (the run stops later, at the unknown reference); a bad item is named.
TEST(Cli, BenchModelListsTakeNoneAndNameABadItem) {
  const CliRun none = palpate("bench model --poisson none --large-strain '' --references nothing");
  EXPECT_EQ(none.code, 1) << none.out;
  EXPECT_NE(none.out.find("reference 'nothing' is not one of"), std::string::npos) << none.out;
  const CliRun bad = palpate("bench model --poisson 0.3,x");
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("--poisson: 'x' is not a number in [0, 0.49]"), std::string::npos) << bad.out;
  const CliRun high = palpate("bench model --large-strain 0.5");
  EXPECT_NE(high.out.find("--large-strain: '0.5' is not a number in [0, 0.49]"), std::string::npos) << high.out;
  const CliRun adaptive = palpate("bench model --adaptive-poisson 0.45,0.6");
  EXPECT_EQ(adaptive.code, 2) << adaptive.out;
  EXPECT_NE(adaptive.out.find("--adaptive-poisson: '0.6' is not a number in [0, 0.49]"), std::string::npos) << adaptive.out;
}

// The browser device is the live page: without --serve there is nothing to steer it; refused before any output.
TEST(Cli, BrowserDeviceWithoutServeIsRefusedBeforeAnyOutput) {
  const std::string out = tmp("browser_no_serve");
  const CliRun r = palpate("record scenes/bunny_touch.json --device browser -q --out " + out);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--device browser: the live page is the device; give --serve"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace palpate
