// End to end: lockstep recordings through the real servo, lattice, OSMesa/EGL renderer and PNG writer.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "render/png_io.h"
#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/json_file.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

using test::fresh_dir;
using test::read_json;

TEST(Record, CubePressWritesThirtyFramesThatChangeWhereTheToolPresses) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  RecordOptions opt;
  opt.out_dir = fresh_dir("cube_press");
  opt.duration_s = 0.5;
  opt.quiet = true;
  auto r = record_scene(scene, opt);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().frames_written, 30);

  const fs::path frames = fs::path(opt.out_dir) / "frames";
  int count = 0;
  for (const auto& e : fs::directory_iterator(frames)) count += e.path().extension() == ".png";
  EXPECT_EQ(count, 30);
  auto first = read_png((frames / "frame_00000.png").string());
  auto last = read_png((frames / "frame_00029.png").string());
  ASSERT_TRUE(first && last);
  ASSERT_EQ(first.value().width, scene.render.width);
  ASSERT_EQ(first.value().height, scene.render.height);
  // the renderer's frames are opaque: stored as 8-bit RGB (IHDR colour type 2), two encoder threads in lockstep
  for (const char* name : {"frame_00000.png", "frame_00029.png"}) {
    std::ifstream png(frames / name, std::ios::binary);
    char head[26] = {};
    png.read(head, sizeof head);
    EXPECT_EQ(std::string(head + 12, 4), "IHDR");
    EXPECT_EQ(head[25], 2) << name;
  }

  const auto summary = read_json(r.value().summary_path);
  EXPECT_GT(summary["max_displacement_m"].get<double>(), 1e-4);
  EXPECT_GT(summary["max_force_N"].get<double>(), 0.1);
  EXPECT_EQ(summary["frames_written"].get<int>(), 30);
  EXPECT_EQ(summary["servo_ticks"].get<int>(), 500);
  EXPECT_EQ(summary["nan_events"].get<int>(), 0);
  EXPECT_EQ(summary["png"]["threads"].get<int>(), kLockstepPngThreads);

  // changed pixels: there are some, and they sit in the image column above the press point
  const auto& a = first.value().rgba;
  const auto& b = last.value().rgba;
  const int w = scene.render.width, h = scene.render.height;
  int changed = 0;
  double cx = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = 4 * (static_cast<std::size_t>(y) * w + x);
      if (std::abs(a[i] - b[i]) + std::abs(a[i + 1] - b[i + 1]) + std::abs(a[i + 2] - b[i + 2]) > 24) {
        ++changed;
        cx += x;
      }
    }
  ASSERT_GT(changed, 50);
  EXPECT_LT(changed, w * h / 4);  // a local change, not the whole picture
  cx /= changed;
  EXPECT_NEAR(cx, w / 2.0, w * 0.2);  // the press is at the middle of the top face
}

TEST(Record, TwoLockstepRunsGiveTheSameStateHash) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  RecordOptions opt;
  opt.duration_s = 0.6;
  opt.quiet = true;
  const std::string dir_a = fresh_dir("det_a"), dir_b = fresh_dir("det_b");
  opt.out_dir = dir_a;
  auto a = record_scene(scene, opt);
  opt.out_dir = dir_b;
  auto b = record_scene(scene, opt);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a.value().state_hash.size(), 16u);
  EXPECT_EQ(a.value().state_hash, b.value().state_hash);
  // the frames too, pixel for pixel, and they show the press: the last frame differs from the first
  auto frame = [](const std::string& dir, const char* name) {
    auto png = read_png((fs::path(dir) / "frames" / name).string());
    EXPECT_TRUE(png) << dir << "/" << name;
    return png ? png.value().rgba : std::vector<uint8_t>{};
  };
  const auto last_a = frame(dir_a, "frame_00035.png");
  ASSERT_FALSE(last_a.empty());
  EXPECT_EQ(last_a, frame(dir_b, "frame_00035.png"));
  EXPECT_NE(last_a, frame(dir_a, "frame_00000.png"));
  // and the hash sees the state: a different scene duration ends elsewhere
  opt.duration_s = 0.4;
  opt.out_dir = fresh_dir("det_c");
  auto c = record_scene(scene, opt);
  ASSERT_TRUE(c);
  EXPECT_NE(a.value().state_hash, c.value().state_hash);
}

TEST(Record, HapticCsvHasOneRowPerServoTick) {
  Scene scene = load_scene(test::source_path("scenes/bunny_pull.json")).value();
  RecordOptions opt;
  opt.duration_s = 1.5;
  opt.quiet = true;
  opt.render = false;
  opt.out_dir = fresh_dir("csv");
  auto r = record_scene(scene, opt);
  ASSERT_TRUE(r) << r.error().message;
  std::ifstream f(fs::path(opt.out_dir) / "haptic.csv");
  std::string line;
  std::getline(f, line);
  EXPECT_EQ(line.rfind("tick,t_s,tool_x_m", 0), 0u);
  int rows = 0, grabbed = 0;
  while (std::getline(f, line)) {
    ++rows;
    // contact column: 2 = grab
    int commas = 0;
    std::size_t pos = 0;
    while (commas < 11 && (pos = line.find(',', pos)) != std::string::npos) ++commas, ++pos;
    if (line[pos] == '2') ++grabbed;
  }
  EXPECT_EQ(rows, 1500);
  EXPECT_GT(grabbed, 300);  // the button is pressed from t = 1.0 s
  EXPECT_FALSE(fs::exists(fs::path(opt.out_dir) / "haptic.csv.partial"));
  // the summary names the complete log and counts its rows
  const auto summary = read_json(r.value().summary_path);
  EXPECT_EQ(summary["haptic_rows"].get<int>(), rows);
  EXPECT_EQ(summary["outputs"]["haptic_csv"], (fs::path(opt.out_dir) / "haptic.csv").string());
  EXPECT_FALSE(summary["outputs"].contains("haptic_csv_error"));
}

// rows of a haptic.csv after its header
int csv_rows(const fs::path& csv) {
  std::ifstream f(csv);
  std::string line;
  int rows = -1;
  while (std::getline(f, line)) ++rows;
  return rows;
}

// A stop request (Ctrl-C, SIGTERM) ends a run after the frame under way with every output whole: the frames so far,
// haptic.csv up to the last tick, summary.json saying where it stopped
TEST(Record, AStopRequestEndsTheRunWithEveryOutputWhole) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  std::atomic<bool> stop{true};
  RecordOptions opt;
  opt.quiet = true;
  opt.out_dir = fresh_dir("stopped");
  opt.stop = &stop;
  auto r = record_scene(scene, opt);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ(r.value().frames_written, 1);
  EXPECT_NE(r.value().interrupted.find("after 1 frame(s)"), std::string::npos) << r.value().interrupted;
  const auto summary = read_json(r.value().summary_path);
  EXPECT_NE(summary.value("interrupted", "").find("after 1 frame(s)"), std::string::npos) << summary.dump();
  // (frame 0 comes before the first tick: the log holds its header only)
  EXPECT_EQ(summary["haptic_rows"].get<int>(), csv_rows(fs::path(opt.out_dir) / "haptic.csv"));
  EXPECT_FALSE(fs::exists(fs::path(opt.out_dir) / "haptic.csv.partial"));
  // without a request the same run goes to its end
  stop = false;
  opt.duration_s = 0.1;
  auto whole = record_scene(scene, opt);
  ASSERT_TRUE(whole) << whole.error().message;
  EXPECT_TRUE(whole.value().interrupted.empty());
  EXPECT_FALSE(read_json(whole.value().summary_path).contains("interrupted"));
}

// ... and through the command: SIGINT to a realtime recording of ten minutes ends it, exit 130, outputs whole, the
// progress line ending where it stopped; SIGHUP (the SSH session the run was started from dropped) the same; a
// second Ctrl-C within the second (an impatient hand, or `timeout` passing the signal on) is the same request
TEST(Record, CtrlCEndsARealtimeRecordingWithItsLogAndSummary) {
  for (const std::string sig : {"INT", "HUP", "INT; sleep 0.2; kill -INT $p"}) {
    const std::string out = fresh_dir("signal_" + std::to_string(sig.size()));
    // the signal goes once the log is open (the handler is in place before it is); timeout passes it on, and ends a
    // run that ignores it in 2 minutes instead of 10
    const test::CliRun r = test::shell(
        "(timeout 120 " + test::palpate_path() + " record scenes/cube_press.json --mode realtime --no-render --duration 600 -o " +
        out + " & p=$!; n=0; while [ ! -e " + out + "/haptic.csv.partial ] && [ $n -lt 300 ]; do sleep 0.1; n=$((n+1)); "
        "done; sleep 0.5; kill -" + sig + " $p; wait $p; echo \"exit $?\")");
    EXPECT_NE(r.out.find("exit 130"), std::string::npos) << sig << ": " << r.out;
    EXPECT_NE(r.out.find("stopped on request"), std::string::npos) << sig << ": " << r.out;
    // the progress line's last word is where the run stopped, not the frames it never made
    EXPECT_NE(r.out.find("record cube_press:"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("frame 36000 / 36000"), std::string::npos) << sig << ": " << r.out;
    const auto summary = read_json(out + "/summary.json");
    EXPECT_TRUE(summary.contains("interrupted")) << summary.dump();
    EXPECT_GT(summary["haptic_rows"].get<int>(), 0);
    EXPECT_EQ(summary["haptic_rows"].get<int>(), csv_rows(fs::path(out) / "haptic.csv"));
  }
}

// ... and one that lands after the run's last frame, while the video is made from the frames, is a stop too: the
// encode ends between frames (no half-made MP4), exit 130, summary.json says so, every frame and tick is kept
TEST(Record, CtrlCWhileTheVideoIsMadeAfterTheRunIsAStopThatKeepsTheFrames) {
  const std::string out = fresh_dir("signal_video");
  const test::CliRun r = test::shell(
      "(timeout 120 " + test::palpate_path() + " record scenes/cube_press.json --mode realtime --duration 4 -q -o " + out +
      " & p=$!; n=0; while ! ls " + out + "/recording.mp4.* >/dev/null 2>&1 && [ $n -lt 3000 ]; do sleep 0.01; "
      "n=$((n+1)); done; kill -INT $p; wait $p; echo \"exit $?\")");
  EXPECT_NE(r.out.find("exit 130"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("after the run's last frame"), std::string::npos) << r.out;
  const auto summary = read_json(out + "/summary.json");
  EXPECT_NE(summary.value("interrupted", "").find("after the run's last frame"), std::string::npos) << summary.dump();
  EXPECT_FALSE(fs::exists(out + "/recording.mp4"));
  EXPECT_EQ(summary["haptic_rows"].get<int>(), csv_rows(fs::path(out) / "haptic.csv"));
  int pngs = 0;
  for (const auto& e : fs::directory_iterator(out + "/frames")) pngs += e.path().extension() == ".png";
  EXPECT_GT(pngs, 200);  // 240 scene frames, a few of them skipped by a loaded machine
  for (const auto& e : fs::directory_iterator(out)) EXPECT_EQ(e.path().filename().string().find(".mp4."), std::string::npos);
}

// ... while a run that Ctrl-C ends before its last frame still gets its whole video, made from the frames it kept
TEST(Record, CtrlCDuringARealtimeRunStillMakesItsVideoFromTheFramesKept) {
  const std::string out = fresh_dir("signal_run_video");
  const test::CliRun r = test::shell(
      "(timeout 120 " + test::palpate_path() + " record scenes/cube_press.json --mode realtime --duration 600 -q -o " + out +
      " & p=$!; n=0; while [ ! -e " + out + "/haptic.csv.partial ] && [ $n -lt 300 ]; do sleep 0.1; n=$((n+1)); "
      "done; sleep 1; kill -INT $p; wait $p; echo \"exit $?\")");
  EXPECT_NE(r.out.find("exit 130"), std::string::npos) << r.out;
  const auto summary = read_json(out + "/summary.json");
  EXPECT_TRUE(summary.contains("interrupted")) << summary.dump();
  ASSERT_TRUE(summary["video"].value("enabled", false)) << summary["video"].dump();
  EXPECT_EQ(summary["video"]["frames"].get<int64_t>(), summary["frames_written"].get<int64_t>());
  EXPECT_TRUE(fs::exists(out + "/recording.mp4"));
}

}  // namespace
}  // namespace palpate

namespace palpate {
namespace {

TEST(Record, RealtimeRunOnRealThreadsKeepsEverySample) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  RecordOptions opt;
  opt.out_dir = fresh_dir("realtime");
  opt.override_mode = true;
  opt.mode = RunMode::kRealtime;
  opt.duration_s = 0.5;
  opt.quiet = true;
  opt.render = false;
  auto r = record_scene(scene, opt);
  ASSERT_TRUE(r) << r.error().message;
  const auto summary = read_json(r.value().summary_path);
  EXPECT_EQ(summary["mode"], "realtime");
  const int64_t ticks = summary["servo_ticks"].get<int64_t>();
  const int64_t overruns = summary["servo"]["overruns"].get<int64_t>();
  // every period is either ticked or counted as missed, and every tick reaches haptic.csv
  EXPECT_NEAR(static_cast<double>(ticks + overruns), 500.0, 3.0);
  EXPECT_EQ(summary["dropped_samples"].get<int64_t>(), 0);
  EXPECT_EQ(summary["haptic_rows"].get<int64_t>(), ticks);
  EXPECT_GT(summary["servo"]["latency_us"]["count"].get<int64_t>(), 0);
  EXPECT_EQ(summary["nan_events"].get<int64_t>(), 0);
  // the window used (adaptive by default, within its cap) and what the machine took, read around the run
  EXPECT_TRUE(summary["servo"]["spin_adaptive"].get<bool>());
  EXPECT_GT(summary["servo"]["spin_us"].get<int64_t>(), 0);
  EXPECT_LE(summary["servo"]["spin_us"].get<int64_t>(), max_spin_window_ns(1'000'000) / 1000);
  EXPECT_GE(summary["servo"]["steal_ms"].get<double>(), 0.0) << summary["servo"].dump();
  EXPECT_GE(summary["servo"]["involuntary_switches"].get<int64_t>(), 0) << summary["servo"].dump();
}

}  // namespace
}  // namespace palpate
