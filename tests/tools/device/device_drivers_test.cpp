// The replay and plugin drivers and the shim's connect-time checks, through the real palpate binary.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>

#include <cstring>
#include <filesystem>
#include <sstream>

#include "haptics/shim/palpate_shim.h"
#include "runtime/session/haptic_log.h"
#include "tools/device/device_process.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;
using test::Child;

struct CmdRun {
  int code = -1;
  std::string out;
};

CmdRun palpate(const std::vector<std::string>& args, const std::string& tag) {
  std::vector<std::string> a = {test::bin_dir() + "/palpate"};
  a.insert(a.end(), args.begin(), args.end());
  const std::string out = (fs::path(test::temp_root()) / ("palpate_drv_" + tag + ".out")).string();
  Child c(a, out);
  CmdRun r;
  r.code = c.wait(120.0);
  r.out = c.output();
  return r;
}

std::string out_dir(const std::string& tag) {
  const fs::path p = fs::path(test::temp_root()) / ("palpate_drv_" + tag);
  fs::remove_all(p);
  return p.string();
}

std::string hash_of(const std::string& dir) {
  return nlohmann::json::parse(test::read_file(dir + "/summary.json"))["state_hash"].get<std::string>();
}

std::string plugin_path() { return test::bin_dir() + "/../lib/libpalpate_emulated_plugin.so"; }

TEST(ReplayDriver, LockstepReplayOfARecordingReproducesItsStateHash) {
  const std::string a = out_dir("replay_src"), b = out_dir("replay_dst");
  CmdRun r1 = palpate({"record", "scenes/cube_press.json", "--duration", "0.8", "--no-render", "-q", "--out", a}, "r1");
  ASSERT_EQ(r1.code, 0) << r1.out;
  CmdRun r2 = palpate({"record", "scenes/cube_press.json", "--duration", "0.8", "--no-render", "-q", "--out", b,
                    "--device", "replay:" + a},
                   "r2");
  ASSERT_EQ(r2.code, 0) << r2.out;
  EXPECT_EQ(hash_of(a), hash_of(b));
  EXPECT_EQ(nlohmann::json::parse(test::read_file(b + "/summary.json"))["device"]["driver"], "replay");
  // and the replayed log equals the original, row for row
  EXPECT_EQ(test::read_file(a + "/haptic.csv"), test::read_file(b + "/haptic.csv"));
}

// haptic.csv's rows (the header left out), split at commas.
std::vector<std::vector<std::string>> csv_rows(const std::string& path) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(test::read_file(path));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream l(line);
    for (std::string c; std::getline(l, c, ',');) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

// A realtime run follows the wall clock: its frames take what the servo queued by then, and its ticks feel a frame's
// patch from whenever it was published (rendering in between, on a shared machine). Replayed in lockstep, the
// recorded order of ticks and frames (haptic.csv's frame and model_frame) is followed, so the replay is the session:
// every tick's force as it was, not a fresh run of the same hand on a virtual clock.
TEST(ReplayDriver, ARealtimeRecordingReplaysTickForTick) {
  const std::string a = out_dir("replay_rt_src"), b = out_dir("replay_rt_dst");
  // a grab and pull with frames drawn (no video): several ticks pass while each frame computes and draws
  CmdRun r1 = palpate({"record", "scenes/bunny_pull_springs.json", "--duration", "4", "--mode", "realtime", "--no-video", "-q",
                       "--out", a},
                      "rt1");
  ASSERT_EQ(r1.code, 0) << r1.out;
  CmdRun r2 = palpate({"record", "scenes/bunny_pull_springs.json", "--no-render", "-q", "--out", b, "--device", "replay:" + a},
                      "rt2");
  ASSERT_EQ(r2.code, 0) << r2.out;
  const auto live = csv_rows(a + "/haptic.csv"), replay = csv_rows(b + "/haptic.csv");
  ASSERT_GT(live.size(), 3000u);
  ASSERT_EQ(replay.size(), live.size()) << "the replay makes the recorded ticks, no more, no fewer";
  // how unlike a lockstep run the realtime one was: ticks that felt a patch older than the frame due at their time
  int64_t late_patch = 0, grab = 0, differing = 0;
  double worst_N = 0.0;
  for (std::size_t i = 0; i < live.size(); ++i) {
    ASSERT_EQ(live[i].size(), static_cast<std::size_t>(kHapticLogWidth));
    ASSERT_EQ(replay[i][0], live[i][0]) << "row " << i;
    const int64_t tick = std::stoll(live[i][0]), felt = std::stoll(live[i][15]);
    late_patch += felt >= 0 && felt < tick * 60 / 1000;
    grab += live[i][11] == "2";
    double d = 0.0;
    for (int c = 8; c <= 10; ++c) d = std::max(d, std::abs(std::stod(replay[i][c]) - std::stod(live[i][c])));
    worst_N = std::max(worst_N, d);
    differing += replay[i] != live[i];
  }
  std::printf("[ figures ] %zu ticks, %lld in a grab, %lld felt a patch older than a lockstep run's; the replay's "
              "largest force difference %.3g N, rows that differ %lld\n",
              live.size(), static_cast<long long>(grab), static_cast<long long>(late_patch), worst_N,
              static_cast<long long>(differing));
  EXPECT_GT(grab, 1000) << "the pull never grabbed";
  EXPECT_GT(late_patch, 100) << "the realtime run went as a lockstep run would: nothing to follow";
  EXPECT_LE(worst_N, 0.02);
  EXPECT_EQ(differing, 0) << "the replay is the session, row for row";
}

// A replay made from another scene is allowed (the same hand against another object) but said; from its own scene
// it is not.
TEST(ReplayDriver, ReplayFromAnotherSceneIsSaid) {
  const std::string a = out_dir("replay_other_src");
  CmdRun r1 = palpate({"record", "scenes/cube_press.json", "--duration", "0.2", "--no-render", "-q", "--out", a}, "o1");
  ASSERT_EQ(r1.code, 0) << r1.out;
  CmdRun same = palpate({"record", "scenes/cube_press.json", "--duration", "0.2", "--no-render", "-q", "--out",
                         out_dir("replay_same_dst"), "--device", "replay:" + a},
                        "o2");
  ASSERT_EQ(same.code, 0) << same.out;
  EXPECT_EQ(same.out.find("recorded from scene"), std::string::npos) << same.out;
  CmdRun other = palpate({"record", "scenes/bunny_touch.json", "--duration", "0.2", "--no-render", "-q", "--out",
                          out_dir("replay_other_dst"), "--device", "replay:" + a},
                         "o3");
  ASSERT_EQ(other.code, 0) << other.out;
  EXPECT_NE(other.out.find("palpate: warning: replay '" + a + "' was recorded from scene 'scenes/cube_press.json', "
                           "this run is 'scenes/bunny_touch.json'"),
            std::string::npos)
      << other.out;
}

TEST(ReplayDriver, MalformedLogNamesTheLine) {
  const std::string csv = (fs::path(test::temp_root()) / "palpate_bad_haptic.csv").string();
  std::ofstream(csv) << "tick,t_s,tool_x_m,tool_y_m,tool_z_m,buttons\n0,0.000,0,0,0.04,0\n1,0.001,0,zz,0.04,0\n";
  CmdRun r = palpate({"record", "scenes/cube_press.json", "--no-render", "-q", "--out", out_dir("bad"), "--device",
                   "replay:" + csv},
                  "bad");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("line 3: column 'tool_y_m': 'zz' is not a finite number"), std::string::npos) << r.out;
}

// A recording whose summary says a frame was skipped that its log names (an edited or mismatched summary) is refused
// with a line naming the log and the frame, before any output is made.
TEST(ReplayDriver, ASkippedFrameTheLogNamesIsRefusedNamingIt) {
  const std::string a = out_dir("replay_skip_src"), b = out_dir("replay_skip_dst");
  CmdRun r1 = palpate({"record", "scenes/cube_press.json", "--duration", "0.3", "--no-render", "-q", "--out", a}, "s1");
  ASSERT_EQ(r1.code, 0) << r1.out;
  auto summary = nlohmann::json::parse(test::read_file(a + "/summary.json"));
  summary["sim"]["skipped_frames"] = {5};
  std::ofstream(a + "/summary.json") << summary.dump(1);
  CmdRun r2 = palpate({"record", "scenes/cube_press.json", "--duration", "0.3", "--no-render", "-q", "--out", b,
                       "--device", "replay:" + a},
                      "s2");
  EXPECT_EQ(r2.code, 1);
  EXPECT_NE(r2.out.find("replay '" + a + "': frame 5 is named in the log but was skipped"), std::string::npos) << r2.out;
  EXPECT_FALSE(fs::exists(b)) << "an output made for a replay that was refused";
}

TEST(PluginDriver, EmulatedPluginReproducesTheScriptedRecording) {
  ASSERT_TRUE(fs::exists(plugin_path())) << plugin_path();
  const std::string a = out_dir("plug_ref"), b = out_dir("plug_run");
  CmdRun r1 = palpate({"record", "scenes/cube_press.json", "--duration", "0.8", "--no-render", "-q", "--out", a}, "p1");
  ASSERT_EQ(r1.code, 0) << r1.out;
  CmdRun r2 = palpate({"record", "scenes/cube_press.json", "--duration", "0.8", "--no-render", "-q", "--out", b,
                    "--device", "plugin:" + plugin_path()},
                   "p2");
  ASSERT_EQ(r2.code, 0) << r2.out;
  EXPECT_EQ(hash_of(a), hash_of(b));
  const auto s = nlohmann::json::parse(test::read_file(b + "/summary.json"));
  EXPECT_EQ(s["device"]["driver"], "plugin");
  EXPECT_EQ(s["device"]["name"], "emulated hand device");
  EXPECT_GT(s["max_force_N"].get<double>(), 0.1);
}

TEST(PluginDriver, LoadErrorsNameTheFile) {
  CmdRun r = palpate({"record", "scenes/cube_press.json", "--no-render", "-q", "--out", out_dir("nolib"), "--device",
                   "plugin:/nonexistent/libx.so"},
                  "nolib");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("plugin '/nonexistent/libx.so'"), std::string::npos) << r.out;
  // a shared object that is not a device plugin
  const std::string not_plugin = "/lib/x86_64-linux-gnu/libm.so.6";
  if (fs::exists(not_plugin)) {
    CmdRun r2 = palpate({"record", "scenes/cube_press.json", "--no-render", "-q", "--out", out_dir("libm"), "--device",
                      "plugin:" + not_plugin},
                     "libm");
    EXPECT_EQ(r2.code, 1);
    EXPECT_NE(r2.out.find("no symbol 'palpate_plugin_entry'"), std::string::npos) << r2.out;
  }
}

// A segment made by hand, as a foreign or outdated peer would leave it.
void make_segment(const std::string& name, mode_t mode, uint32_t version, uint32_t size) {
  const std::string path = std::string(PALPATE_SHIM_PREFIX) + name;
  shm_unlink(path.c_str());
  const int fd = shm_open(path.c_str(), O_RDWR | O_CREAT | O_EXCL, mode);
  ASSERT_GE(fd, 0);
  fchmod(fd, mode);
  ASSERT_EQ(ftruncate(fd, size), 0);
  void* p = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  close(fd);
  ASSERT_NE(p, MAP_FAILED);
  auto* h = static_cast<palpate_shim_header*>(p);
  h->version = version;
  h->segment_size = size;
  h->magic = PALPATE_SHIM_MAGIC;
  munmap(p, size);
}

CmdRun record_against(const std::string& name, const std::string& tag) {
  return palpate({"record", "scenes/cube_press.json", "--no-render", "-q", "--duration", "0.2", "--out", out_dir(tag),
                  "--device", "shm:" + name},
                 tag);
}

TEST(ShimConnect, VersionMismatchIsAClearErrorAtConnect) {
  const std::string name = test::link_name("ver");
  make_segment(name, 0600, 99, sizeof(palpate_shim_segment));
  CmdRun r = record_against(name, "ver");
  shm_unlink((std::string(PALPATE_SHIM_PREFIX) + name).c_str());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("device speaks shim version 99, this build speaks version 1"), std::string::npos) << r.out;
}

TEST(ShimConnect, SizeMismatchIsAClearErrorAtConnect) {
  const std::string name = test::link_name("size");
  make_segment(name, 0600, PALPATE_SHIM_VERSION, 512);
  CmdRun r = record_against(name, "size");
  shm_unlink((std::string(PALPATE_SHIM_PREFIX) + name).c_str());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("segment size 512 (file 512 bytes), this build expects 448"), std::string::npos) << r.out;
}

TEST(ShimConnect, SegmentOthersCanAccessIsRefused) {
  const std::string name = test::link_name("mode");
  make_segment(name, 0644, PALPATE_SHIM_VERSION, sizeof(palpate_shim_segment));
  CmdRun r = record_against(name, "mode");
  shm_unlink((std::string(PALPATE_SHIM_PREFIX) + name).c_str());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("mode 0644 lets other users access it"), std::string::npos) << r.out;
}

TEST(ShimConnect, BadLinkNameIsRefused) {
  CmdRun r = record_against("../etc", "name");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("shm name '../etc': character '/'"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace palpate
