// The record plan: a pure function from the scene and the command line's options to the mode, rates, driver,
// video policy and paths of a run, and the checks of every output before anything in the output folder is touched.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "support/fixtures.h"
#include "runtime/record/record_plan.h"
#include "runtime/session/device_factory.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

Scene cube() { return load_scene(test::source_path("scenes/cube_press.json")).value(); }

// The default video of `palpate record` (on, at <out>/recording.mp4, a warning when it cannot be made).
RecordOptions default_video(const std::string& out) {
  RecordOptions o;
  o.out_dir = out;
  o.quiet = true;
  o.video_optional = true;
  return o;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(RecordPlan, ResolvesModeRatesDriverVideoAndPathsOnce) {
  const Scene s = cube();
  RecordOptions o = default_video("");
  auto p = plan_record(s, o);
  ASSERT_TRUE(p) << p.error().message;
  EXPECT_TRUE(p.value().lockstep);
  EXPECT_EQ(p.value().mode_from, "scene");
  EXPECT_EQ(p.value().out_dir, (fs::path("out") / s.name).string());
  EXPECT_EQ(p.value().summary_path, (fs::path("out") / s.name / "summary.json").string());
  EXPECT_EQ(p.value().video, VideoPolicy::kDuring);
  EXPECT_EQ(p.value().video_path, (fs::path("out") / s.name / "recording.mp4").string());
  EXPECT_DOUBLE_EQ(p.value().scene.rates.servo_hz, s.rates.servo_hz);
  EXPECT_FALSE(p.value().rate_given);
  // the overrides land in the plan's scene, the one copy the run reads
  o.servo_rate_hz = 2000.0;
  o.duration_s = 0.25;
  o.override_mode = true;
  o.mode = RunMode::kRealtime;
  p = plan_record(s, o);
  ASSERT_TRUE(p);
  EXPECT_DOUBLE_EQ(p.value().scene.rates.servo_hz, 2000.0);
  EXPECT_DOUBLE_EQ(p.value().scene.rates.frame_hz, s.rates.frame_hz);
  EXPECT_TRUE(p.value().rate_given);
  EXPECT_DOUBLE_EQ(p.value().scene.duration_s, 0.25);
  EXPECT_FALSE(p.value().lockstep);
  EXPECT_EQ(p.value().scene.run_mode, RunMode::kRealtime);
  // a realtime run's default video is made after the run, from its frames; an explicit one while recording
  EXPECT_EQ(p.value().video, VideoPolicy::kAfterRun);
  o.video_path = "elsewhere.mp4";
  o.video_optional = false;
  EXPECT_EQ(plan_record(s, o).value().video, VideoPolicy::kDuring);
  // no frames, no video
  o.render = false;
  EXPECT_EQ(plan_record(s, o).value().video, VideoPolicy::kNone);
  const auto warnings = plan_record(s, o).value().warnings;
  EXPECT_NE(std::find(warnings.begin(), warnings.end(), "--video needs frames; --no-render records none"),
            warnings.end());
}

TEST(RecordPlan, ADeviceInAnotherProcessRecordsOnTheWallClockUnlessTold) {
  const Scene s = cube();
  RecordOptions o;
  o.device = "shm:somewhere";
  auto p = plan_record(s, o);
  ASSERT_TRUE(p);
  EXPECT_EQ(p.value().driver, DeviceDriver::kShm);
  EXPECT_FALSE(p.value().lockstep);
  EXPECT_EQ(p.value().mode_from, "shm device");
  o.override_mode = true;
  o.mode = RunMode::kLockstep;
  EXPECT_TRUE(plan_record(s, o).value().lockstep);
  o.device = "bogus";
  auto bad = plan_record(s, o);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("device 'bogus': unknown driver"), std::string::npos) << bad.error().message;
}

// A person's pointer runs on the wall clock: the browser device records in realtime and refuses lockstep.
TEST(RecordPlan, TheBrowserDeviceRecordsInRealtimeAndRefusesLockstep) {
  const Scene s = cube();
  RecordOptions o;
  o.device = "browser";
  auto p = plan_record(s, o);
  ASSERT_TRUE(p);
  EXPECT_EQ(p.value().driver, DeviceDriver::kBrowser);
  EXPECT_FALSE(p.value().lockstep);
  EXPECT_EQ(p.value().mode_from, "browser device");
  o.override_mode = true;
  o.mode = RunMode::kLockstep;
  auto bad = plan_record(s, o);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("--device browser: a person's pointer runs on the wall clock; --mode lockstep"),
            std::string::npos)
      << bad.error().message;
  // without the live view there is no page to be the device
  EXPECT_FALSE(make_device(s, "browser"));
  EXPECT_NE(make_device(s, "browser").error().message.find("needs the live view"), std::string::npos);
}

TEST(RecordPlan, AVideoOnTheRecordingsOwnOutputsIsRefused) {
  const Scene s = cube();
  const std::string out = test::fresh_dir("plan_own");
  RecordOptions o;
  o.out_dir = out;
  for (const auto& [video, says] :
       {std::pair<std::string, std::string>{out + "/summary.json", "is the recording's own summary.json"},
        {out + "/./haptic.csv", "is the recording's own haptic.csv"},
        {out + "/device_events.csv", "is the recording's own device_events.csv"},
        {out + "/frames/frame_00001.png", "is where the recording writes its frames"},
        {out, "is the output folder"}}) {
    o.video_path = video;
    auto p = plan_record(s, o);
    ASSERT_FALSE(p) << video;
    EXPECT_NE(p.error().message.find("--video '" + video + "': " + says), std::string::npos) << p.error().message;
  }
  o.video_path = out + "/frames.mp4";  // beside them is fine
  EXPECT_TRUE(plan_record(s, o));
}

TEST(RecordPlan, OutputsAreCheckedBeforeTheOutputFolderIsTouched) {
  const Scene s = cube();
  const std::string base = test::fresh_dir("plan_check");
  fs::create_directories(base);
  RecordOptions o;
  o.out_dir = base + "/out";
  o.video_path = base + "/nodir/x.mp4";
  auto missing = check_plan_outputs(plan_record(s, o).value());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("video '" + o.video_path + "': folder '" + base + "/nodir' does not exist"),
            std::string::npos) << missing.error().message;
  // a folder nobody may create files in (root included)
  o.video_path = "/proc/x.mp4";
  auto readonly = check_plan_outputs(plan_record(s, o).value());
  ASSERT_FALSE(readonly);
  EXPECT_NE(readonly.error().message.find("video '/proc/x.mp4': cannot write in folder '/proc'"), std::string::npos)
      << readonly.error().message;
  // the output folder is a file
  std::ofstream(base + "/file") << "x";
  o.out_dir = base + "/file";
  o.video_path.clear();
  auto not_folder = check_plan_outputs(plan_record(s, o).value());
  ASSERT_FALSE(not_folder);
  EXPECT_NE(not_folder.error().message.find("output '" + base + "/file': is not a folder"), std::string::npos);
  o.out_dir = base + "/new/deeper";  // created by the run
  EXPECT_TRUE(check_plan_outputs(plan_record(s, o).value()));
}

TEST(RecordPlan, ARefusedVideoLeavesThePreviousRunWhole) {
  Scene s = cube();
  s.duration_s = 0.1;
  const std::string out = test::fresh_dir("plan_keep");
  RecordOptions o = default_video(out);
  auto first = record_scene(s, o);
  ASSERT_TRUE(first) << first.error().message;
  const std::string summary = slurp(fs::path(out) / "summary.json");
  ASSERT_FALSE(summary.empty());
  for (const std::string& video : {out + "/nodir/x.mp4", out + "/summary.json", out + "/frames/frame_00002.png",
                                   std::string("/proc/x.mp4")}) {
    o.video_path = video;
    o.video_optional = false;
    auto r = record_scene(s, o);
    ASSERT_FALSE(r) << video;
    EXPECT_EQ(slurp(fs::path(out) / "summary.json"), summary) << video;
    EXPECT_TRUE(fs::exists(fs::path(out) / "haptic.csv")) << video;
    EXPECT_TRUE(fs::exists(fs::path(out) / "frames" / "frame_00005.png")) << video;  // 6 frames in 0.1 s
    EXPECT_TRUE(fs::exists(fs::path(out) / "recording.mp4")) << video;
  }
}

TEST(RecordPlan, ARealtimeRunsVideoIsInTheOneSummaryWritten) {
  Scene s = cube();
  s.duration_s = 0.2;
  const std::string out = test::fresh_dir("plan_after");
  RecordOptions o = default_video(out);
  o.override_mode = true;
  o.mode = RunMode::kRealtime;
  o.fifo_priority = 0;
  o.lock_memory = false;
  auto r = record_scene(s, o);
  ASSERT_TRUE(r) << r.error().message;
  // the summary returned is the file: nothing rewrote it after the run
  EXPECT_EQ(slurp(fs::path(out) / "summary.json"), r.value().summary_json);
  const auto j = nlohmann::json::parse(r.value().summary_json);
  ASSERT_TRUE(j["video"]["enabled"].get<bool>()) << j["video"].dump();
  EXPECT_EQ(j["video"]["made"], "after the realtime run, from frames/");
  EXPECT_EQ(j["video"]["frames"].get<int64_t>(), r.value().frames_written);
  EXPECT_EQ(j["video"]["frame_rate_hz"].get<int>(), 60);
  EXPECT_EQ(r.value().video_path, out + "/recording.mp4");
  EXPECT_TRUE(fs::exists(r.value().video_path));
}

}  // namespace
}  // namespace palpate
