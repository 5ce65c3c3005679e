// Hostile input through the palpate command: limits named, devices never replaced, nothing written for a
// refused input, divergence never silent.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/read_file.h"
#include "support/temp_root.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

using test::CliRun;
using test::palpate;
using test::read_file;

std::string tmp(const std::string& name) { return test::temp_path("hostile_", name); }

std::string write(const std::string& name, const std::string& text) {
  const std::string path = tmp(name);
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// A box scene pressed from above, with extra top-level text (must start with a comma) and lattice keys.
std::string box_scene(const std::string& name, const std::string& lattice, const std::string& extra = "") {
  return write(name + ".json",
               R"({"mesh": {"box_m": [0.06, 0.06, 0.06], "size_m": 0.06}, "lattice": {)" + lattice +
                   R"(}, "trajectory": [{"t_s": 0, "pos_m": [0.004, 0.004, 0.045]}, {"t_s": 0.3, "pos_m": [0.004, 0.004, 0.012]}], "duration_s": 0.5)" +
                   extra + "}");
}

void expect_error(const CliRun& r, const std::string& needle) {
  EXPECT_TRUE(r.code == 1 || r.code == 2) << "exit " << r.code << ": " << r.out;
  EXPECT_NE(r.out.find(needle), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one line expected: " << r.out;
}

// `palpate ARGS` with files capped at `blocks` of the shell's ulimit -f (512 bytes for sh): writes past it fail
// with EFBIG as a full disk's fail with ENOSPC.
CliRun palpate_with_file_limit(int blocks, const std::string& args) {
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  return test::shell("ulimit -f " + std::to_string(blocks) + "; " + std::string(bin ? bin : "build/bin") + "/palpate " + args);
}

bool is_char_device(const char* path) {
  struct stat s {};
  return ::stat(path, &s) == 0 && S_ISCHR(s.st_mode);
}

TEST(Hostile, HelpNamesTheLimitsOnce) {
  const CliRun r = palpate("--help");
  EXPECT_EQ(r.code, 0);
  EXPECT_NE(r.out.find("65536 nodes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("scene file 16 MiB"), std::string::npos) << r.out;
  // a subcommand's help points there instead of repeating the paragraph
  for (const char* cmd : {"record --help", "bench scale --help", "scene --help"}) {
    const CliRun s = palpate(cmd);
    EXPECT_EQ(s.code, 0) << cmd;
    EXPECT_EQ(s.out.find("65536 nodes"), std::string::npos) << cmd << ": " << s.out;
  }
  EXPECT_NE(palpate("record --help").out.find("Limits of inputs: palpate --help"), std::string::npos);
}

TEST(Hostile, HugeLatticeIsRefusedBeforeAnyOutput) {
  const std::string out = tmp("out_huge");
  fs::remove_all(out);
  const std::string s = write("huge.json", R"({"mesh": {"box_m": [0.06, 0.06, 0.06]}, "grid": {"levels": 8},
      "lattice": {"level": 8, "radius_cells": 128}, "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}]})");
  expect_error(palpate("record " + s + " -q --out " + out),
               "lattice.level 8 with radius_cells 128 may reach 2146689 nodes, more than the limit of 65536");
  EXPECT_FALSE(fs::exists(out));
}

TEST(Hostile, AHugeRefinedZoneIsRefusedBeforeAnyOutput) {
  const std::string out = tmp("out_huge_refine");
  fs::remove_all(out);
  const std::string s = write("huge_refine.json", R"({"mesh": {"box_m": [0.06, 0.06, 0.06]}, "grid": {"levels": 8},
      "material": {"young_modulus_Pa": 1e5, "poisson_ratio": 0.25, "density_kg_per_m3": 1000},
      "lattice": {"level": 5, "integrator": "implicit_euler", "refine": {"level": 8, "radius_m": 10}},
      "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}]})");
  expect_error(palpate("record " + s + " -q --out " + out),
               "refined to level 8 within 10 m may reach");
  expect_error(palpate("record " + s + " -q --out " + out), "(lower lattice.refine.level or lattice.refine.radius_m)");
  EXPECT_FALSE(fs::exists(out));
}

TEST(Hostile, AnExplicitSchemeNoSubstepCountCanHoldIsRefusedBeforeAnyOutput) {
  // a 300 kPa silicone on 3.75 mm cells needs thousands of symplectic substeps a frame: every frame would be NaN
  const std::string out = tmp("out_stiff_explicit");
  fs::remove_all(out);
  const std::string s = write("stiff_explicit.json", R"({"mesh": {"box_m": [0.06, 0.06, 0.06]}, "grid": {"levels": 5},
      "material": {"young_modulus_Pa": 3e5, "poisson_ratio": 0.45, "density_kg_per_m3": 1070, "model": "volumetric",
                   "stiffness_damping_s": 2e-3},
      "lattice": {"level": 5, "integrator": "symplectic_euler"},
      "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}]})");
  expect_error(palpate("record " + s + " -q --out " + out), "lattice.integrator 'symplectic_euler' needs");
  expect_error(palpate("record " + s + " -q --out " + out), "choose lattice.integrator 'implicit_euler'");
  EXPECT_FALSE(fs::exists(out));
}

// The triangles a mesh may have follow the machine's memory (PALPATE_MEMORY_BYTES says it here: 64 MiB holds
// 209715 triangles at 320 bytes each). A binary PLY, OFF or binary STL declaring more faces is refused from its
// header: the bodies below are zeros, which a reader would refuse as faces of no corners or a vertex repeated, so
// the message shows the body was never judged. A mesh file is allowed a sixteenth of the memory (at least 64 MiB).
TEST(Hostile, AMeshWithMoreFacesThanTheMemoryHoldsIsRefusedFromItsHeader) {
  const std::string limit = "PALPATE_MEMORY_BYTES=64M " + test::palpate_path();
  const std::string faces = "300000";
  const std::string ply_head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
                               "property float y\nproperty float z\nelement face " + faces +
                               "\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string ply = write("many_faces.ply", ply_head + std::string(36 + 300000 * 13, '\0'));
  std::string off_text = "OFF\n# a comment\n3 " + faces + " 0\n0 0 0\n1 0 0\n0 1 0\n";
  for (int i = 0; i < 300000; ++i) off_text += "3 0 1 2\n";
  const std::string off = write("many_faces.off", off_text);
  std::string stl(80, ' ');
  const uint32_t n = 300000;
  stl.append(reinterpret_cast<const char*>(&n), 4);
  stl.append(std::size_t{50} * n, '\0');
  const std::string bin_stl = write("many_faces.stl", stl);
  for (const std::string& file : {ply, off, bin_stl}) {
    SCOPED_TRACE(file);
    expect_error(test::shell(limit + " info " + file), "the header declares 300000 faces, more than the 209715 "
                                                       "triangles this machine's memory holds (0.1 GiB at 320 bytes a triangle)");
    // the same file where the memory holds it is read (and its body judged)
    const CliRun roomy = test::shell("PALPATE_MEMORY_BYTES=1G " + test::palpate_path() + " info " + file);
    EXPECT_EQ(roomy.out.find("this machine's memory"), std::string::npos) << roomy.out;
  }
  // a file larger than a sixteenth of the memory is refused by its size (here 64 MiB: the floor)
  const std::string big = tmp("big.ply");
  { std::ofstream(big, std::ios::binary) << ply_head; }
  fs::resize_file(big, (int64_t{64} << 20) + 1);
  expect_error(test::shell(limit + " info " + big), "67108865 bytes, more than the limit of 67108864");
  // a PALPATE_MEMORY_BYTES that is not a number is said, and the machine's memory taken
  const CliRun wrong = test::shell("PALPATE_MEMORY_BYTES=lots " + test::palpate_path() + " info " + off);
  EXPECT_NE(wrong.out.find("PALPATE_MEMORY_BYTES 'lots' is not a number of bytes"), std::string::npos) << wrong.out;
  EXPECT_EQ(wrong.out.find("this machine's memory holds"), std::string::npos) << wrong.out;
}

// A bench's output into a folder that does not exist is refused before the minutes of measuring, naming the folder
TEST(Hostile, ABenchOutputIntoAMissingFolderIsRefusedBeforeMeasuring) {
  const std::string json = tmp("no_such_folder") + "/scale.json";
  expect_error(palpate("bench scale scenes/bunny_pull.json --max-subdivisions 0 --json " + json),
               "bench json '" + json + "': folder '" + tmp("no_such_folder") + "' does not exist");
  expect_error(palpate("bench scale scenes/bunny_pull.json --max-subdivisions 0 --plot " + tmp("no_plot_folder") + "/s.png"),
               "folder '" + tmp("no_plot_folder") + "' does not exist");
}

TEST(Hostile, SubdividedModelAndBoxLatticeAreBoundedBeforeBuilding) {
  // more than 2^29 triangles: past what any machine's memory is allowed to hold
  const std::string s = write("subdivided.json", R"({"mesh": {"box_m": [0.06, 0.06, 0.06], "box_subdivisions": 256,
      "subdivisions": 7}, "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}]})");
  expect_error(palpate("record " + s + " -q --out " + tmp("out_subdivided")),
               "786432 triangles with mesh.subdivisions 7 make 12884901888, more than the ");
  expect_error(palpate("record " + s + " -q --out " + tmp("out_subdivided")), "triangles this machine's memory holds");
  EXPECT_FALSE(fs::exists(tmp("out_subdivided")));
  expect_error(palpate("bench sim " + box_scene("box128", "") + " -q --box 128"),
               "bench sim: --box 128 makes 2146689 nodes, more than the limit of 65536");
}

TEST(Hostile, NumberTooLargeForADoubleIsAnErrorNotAnAbort) {
  const std::string s = box_scene("overflow", R"("node_mass_kg": 1e400)");
  expect_error(palpate("record " + s + " -q --out " + tmp("out_overflow")), "scene '" + s + "': invalid JSON");
  expect_error(palpate("bench sim " + s), "scene '" + s + "': invalid JSON");
}

TEST(Hostile, NonFiniteAndOutOfRangeArgumentsAreUsageErrors) {
  const std::string s = box_scene("args", "");
  EXPECT_EQ(palpate("record " + s + " -q --duration nan").code, 2);
  EXPECT_EQ(palpate("bench sim " + s + " --substeps -5").code, 2);
  EXPECT_EQ(palpate("bench sim " + s + " --iterations 100000000").code, 2);
  EXPECT_EQ(palpate("bench loop --seconds nan").code, 2);
}

TEST(Hostile, BenchOutputsNeverReplaceADevice) {
  const std::string s = box_scene("bench_dev", "");
  expect_error(palpate("bench sim " + s + " -q --json /dev/null"), "bench json '/dev/null': is not a regular file");
  expect_error(palpate("bench sim " + s + " -q --plot /dev/null"), "plot '/dev/null': is not a regular file");
  expect_error(palpate("bench loop --scene " + s + " --seconds 0.1 --json /dev/null"),
               "bench json '/dev/null': is not a regular file");
  expect_error(palpate("bench force " + s + " --json /dev/full"), "bench json '/dev/full': is not a regular file");
  EXPECT_TRUE(is_char_device("/dev/null"));
  EXPECT_TRUE(is_char_device("/dev/full"));
}

TEST(Hostile, SceneThatIsNotARegularFileIsRefused) {
  expect_error(palpate("record /dev/zero -q --out " + tmp("out_zero")), "scene '/dev/zero': is not a regular file");
  EXPECT_FALSE(fs::exists(tmp("out_zero")));
}

TEST(Hostile, DeviceErrorsLeaveNoOutputBehind) {
  const std::string s = box_scene("devices", "");
  const std::string bad_csv = write("bad.csv", "tick,t_s\n1,x\n");
  for (const std::string& dev : {std::string("shm:"), std::string("plugin:/nonexistent/p.so"), std::string("bogus"),
                                 std::string("replay:/dev/zero"), "replay:" + bad_csv}) {
    const std::string out = tmp("out_device");
    fs::remove_all(out);
    const CliRun r = palpate("record " + s + " -q --no-render --out " + out + " --device " + dev);
    EXPECT_EQ(r.code, 1) << dev << ": " << r.out;
    EXPECT_FALSE(fs::exists(out)) << dev << " left " << out << " behind";
  }
}

TEST(Hostile, DivergenceIsWarnedAtStartAndFailsTheRun) {
  const std::string s = box_scene("diverge", R"("node_mass_kg": 1e-7, "stiffness_N_per_m": {"structural": 1e9}, "max_substeps": 256)");
  const std::string out = tmp("out_diverge");
  fs::remove_all(out);
  const CliRun r = palpate("record " + s + " -q --no-render --out " + out);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("warning: symplectic_euler needs"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("lattice.max_substeps is 256"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("the lattice diverged: nan_events"), std::string::npos) << r.out;
}

TEST(Hostile, AllowDivergenceAcceptsTheRunWithAWarning) {
  const std::string s = box_scene("diverge_ok", R"("node_mass_kg": 1e-7, "stiffness_N_per_m": {"structural": 1e9}, "max_substeps": 256, "allow_divergence": true)");
  const std::string out = tmp("out_diverge_ok");
  fs::remove_all(out);
  const CliRun r = palpate("record " + s + " -q --no-render --out " + out);
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("palpate: warning: scene '" + s + "': the lattice diverged: nan_events"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("accepted (lattice.allow_divergence)"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(out + "/summary.json"));
}

// An interrupted re-record into a used folder leaves no summary, log or video of the earlier run beside its frames.
TEST(Hostile, ReRecordClearsThePreviousRunBeforeWriting) {
  const std::string s = box_scene("rerecord", "");
  const std::string out = tmp("out_rerecord");
  fs::remove_all(out);
  ASSERT_EQ(palpate("record " + s + " -q --duration 0.1 --no-video --out " + out).code, 0);
  ASSERT_TRUE(fs::exists(out + "/summary.json"));
  ASSERT_TRUE(fs::exists(out + "/haptic.csv"));
  std::ofstream(out + "/recording.mp4") << "an earlier run's video";
  std::ofstream(out + "/device_events.csv") << "an earlier run's events";

  // a long second run, killed once it has started writing
  const CliRun started = test::shell(std::string(std::getenv("PALPATE_BIN_DIR") ? std::getenv("PALPATE_BIN_DIR") : "build/bin") +
                                     "/palpate record " + s + " -q --duration 600 --no-render --out " + out +
                                     " >/dev/null 2>&1 & echo $!");
  const pid_t pid = static_cast<pid_t>(std::atoll(started.out.c_str()));
  ASSERT_GT(pid, 0) << started.out;
  bool writing = false;
  for (int i = 0; i < 6000 && !writing; ++i) {  // up to 60 s on a loaded machine
    writing = fs::exists(out + "/haptic.csv.partial");
    if (!writing) ::usleep(10000);
  }
  ::kill(pid, SIGKILL);
  for (int i = 0; i < 500 && ::kill(pid, 0) == 0; ++i) ::usleep(10000);
  ASSERT_TRUE(writing) << "the second run never started writing";
  for (const char* name : {"summary.json", "haptic.csv", "recording.mp4", "device_events.csv"})
    EXPECT_FALSE(fs::exists(out + "/" + name)) << name << " of the earlier run is still there";
  int frames = 0;
  if (fs::exists(out + "/frames"))
    for (const auto& e : fs::directory_iterator(out + "/frames")) frames += e.path().extension() == ".png";
  EXPECT_EQ(frames, 0) << "frames of the earlier run are still there";
}

// A file-size limit fails writes as a full disk does: the first file that failed is named with errno's text,
// and the process is not killed by SIGXFSZ halfway through its outputs.
TEST(Hostile, FileSizeLimitIsReportedAgainstTheFirstFileLikeAFullDisk) {
  const std::string s = box_scene("fsize", "");
  const std::string out = tmp("out_fsize");
  fs::remove_all(out);
  const CliRun r = palpate_with_file_limit(40, "record " + s + " -q --duration 0.5 --no-video --out " + out);
  expect_error(r, "palpate: 30 frame(s) could not be written: png '" + out + "/frames/frame_00000.png': File too large");
}

// The log cut short by a file-size limit (no frames; the 500 rows, about 90 KB, pass the 32 KiB cap, the summary
// fits under it): summary.json names the file kept and counts the rows that file holds, not the rows the run
// produced, and says why the log is not complete.
TEST(Hostile, SummaryCountsTheHapticRowsTheKeptFileHolds) {
  const std::string s = box_scene("fsize_log", "");
  const std::string out = tmp("out_fsize_log");
  fs::remove_all(out);
  const CliRun r = palpate_with_file_limit(64, "record " + s + " -q --duration 0.5 --no-render --out " + out);
  const std::string log = out + "/haptic.csv", partial = log + ".partial";
  expect_error(r, "palpate: log '" + log + "': File too large (partial data kept in " + partial + ", up to its last whole line)");
  EXPECT_FALSE(fs::exists(log));
  const std::string kept = read_file(partial);
  ASSERT_EQ(kept.rfind("tick,t_s,", 0), 0u) << "no header in " << partial;
  const int64_t rows = std::count(kept.begin(), kept.end(), '\n') - 1;
  ASSERT_TRUE(fs::exists(out + "/summary.json")) << r.out;
  const auto j = nlohmann::json::parse(read_file(out + "/summary.json"));
  EXPECT_EQ(j["haptic_rows"].get<int64_t>(), rows);
  EXPECT_LT(rows, j["servo_ticks"].get<int64_t>()) << "every row fitted: the limit never bit";
  EXPECT_EQ(j["outputs"]["haptic_csv"], partial);
  EXPECT_EQ(j["outputs"]["haptic_csv_error"], r.out.substr(9, r.out.size() - 10));  // the message less "palpate: "
}

TEST(Hostile, DanglingOutputLinkIsNamedAsSuch) {
  const std::string s = box_scene("dangling", "");
  const std::string link = tmp("out_dangling");
  fs::remove_all(link);
  fs::create_symlink(tmp("nowhere/deeper"), link);
  expect_error(palpate("record " + s + " -q --duration 0.1 --no-render --out " + link),
               "output '" + link + "': is a symbolic link to '" + tmp("nowhere/deeper") + "', which does not exist");
  EXPECT_FALSE(fs::exists(tmp("nowhere")));
}

TEST(Hostile, SceneNameCannotSteerTheOutput) {
  const std::string s = write("named.json", R"({"name": "../../escape", "mesh": {"box_m": [0.06, 0.06, 0.06]},
      "trajectory": [{"t_s": 0, "pos_m": [0, 0, 0.05]}]})");
  expect_error(palpate("record " + s + " -q"), "name: '../../escape' must be");
}

// A unit cube with one stray triangle 1e30 away: its bounding box is the triangle's, so the view, the lattice and
// the touch would all miss the body (touch never made contact, pull diverged). `palpate scene` and a recording
// refuse it, naming the stray vertex, and write nothing.
TEST(HostileCli, StrayFarTriangleIsNamedNotFramed) {
  const std::string obj = std::string(PALPATE_SOURCE_DIR) + "/tests/hostile/meshes/obj_cube_with_far_triangle.obj";
  const std::string scene = tmp("far_triangle.json");
  fs::remove(scene);
  expect_error(palpate("scene " + obj + " --out " + scene), "lies 1e+30 units from the bulk of the model");
  EXPECT_FALSE(fs::exists(scene));
  const CliRun r = palpate("scene " + obj + " --out " + scene);
  EXPECT_NE(r.out.find("3 vertices lie more than 1000 times that far out"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace palpate
