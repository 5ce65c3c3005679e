// Out of memory anywhere in a recording ends it with a line, never with an abort: an allocation made to fail on
// purpose, at points spread over a whole lockstep recording (model, frame loop, PNG encoder threads, video encoder,
// summary), in a child process so that an abort shows as a signal. A run stopped in its frame loop or by its PNG
// writer keeps its frames whole, its haptic log and a summary.json that says why it ended.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "support/alloc_counter.h"
#include "support/fixtures.h"
#include "support/read_file.h"
#include "runtime/record/memory_reserve.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

// what a child reports through its pipe
struct ChildReport {
  bool fired = false;
  bool ok = false;
  long long allocations = 0;
  std::string error;
};

RecordOptions options(const std::string& out, bool realtime) {
  RecordOptions opt;
  opt.out_dir = out;
  opt.duration_s = 0.25;
  opt.quiet = true;
  opt.video_path = out + "/recording.mp4";
  if (realtime) {
    // the servo on its own thread at 1 kHz, the frames on the wall clock; no frames drawn, so the recording's
    // allocations are its frame loop's (no encoder threads), and no real-time privileges asked for in a test child
    opt.override_mode = true;
    opt.mode = RunMode::kRealtime;
    opt.duration_s = 1.0;
    opt.render = false;
    opt.video_path.clear();
    opt.fifo_priority = 0;
    opt.lock_memory = false;
  }
  return opt;
}

// Runs the recording in a child; fail_at > 0 makes that allocation (counted over every thread) throw once.
// Returns the report; `signalled` says whether the child died of a signal (an abort); an exception that left
// the recorder fails the test here.
ChildReport run_child(const Scene& scene, const std::string& out, long long fail_at, bool* signalled,
                      bool realtime = false) {
  int fds[2];
  EXPECT_EQ(::pipe(fds), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    ChildReport rep;
    // an exception that escapes the recorder is a failure of its own (exit 3), not gtest's to report in the child
    try {
      test::AllThreadsAllocationGuard count;
      std::optional<test::AllocationFault> fault;
      if (fail_at > 0) fault.emplace(fail_at);
      auto r = record_scene(scene, options(out, realtime));
      rep.ok = static_cast<bool>(r);
      if (!r) rep.error = r.error().message;
      rep.fired = fault && fault->fired();
      rep.allocations = count.count();
    } catch (...) {
      ::_exit(3);
    }
    const std::string line = std::to_string(rep.fired) + " " + std::to_string(rep.ok) + " " +
                             std::to_string(rep.allocations) + " " + rep.error;
    [[maybe_unused]] const ssize_t n = ::write(fds[1], line.data(), line.size());
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string text;
  char buf[512];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  *signalled = WIFSIGNALED(status);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "an exception escaped the recorder";
  ChildReport rep;
  int fired = 0, ok = 0;
  int used = 0;
  if (std::sscanf(text.c_str(), "%d %d %lld %n", &fired, &ok, &rep.allocations, &used) >= 3) {
    rep.fired = fired != 0;
    rep.ok = ok != 0;
    rep.error = text.substr(static_cast<std::size_t>(used));
  }
  return rep;
}

TEST(OutOfMemory, AnywhereInARecordingEndsWithALineAndKeepsWhatWasWritten) {
  const Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  bool signalled = false;
  const ChildReport clean = run_child(scene, test::fresh_dir("oom_clean"), 0, &signalled);
  ASSERT_FALSE(signalled);
  ASSERT_TRUE(clean.ok) << clean.error;
  ASSERT_GT(clean.allocations, 100);

  // points spread over the run's allocations, from loading the model to writing the summary
  constexpr int kPoints = 9;
  int in_run = 0;
  for (int k = 1; k <= kPoints; ++k) {
    const long long at = clean.allocations * k / (kPoints + 1);
    const std::string out = test::fresh_dir("oom_" + std::to_string(k));
    const ChildReport rep = run_child(scene, out, at, &signalled);
    SCOPED_TRACE("allocation " + std::to_string(at) + " of " + std::to_string(clean.allocations));
    ASSERT_FALSE(signalled) << "the recording aborted";
    ASSERT_TRUE(rep.fired);
    if (rep.ok) continue;  // the failure cost only a timing figure
    EXPECT_NE(rep.error.find("out of memory"), std::string::npos) << rep.error;
    const bool stopped_in_run = rep.error.find("in frame") != std::string::npos ||
                                rep.error.find("while encoding") != std::string::npos;
    if (!stopped_in_run) continue;  // opening or finishing: said on the line
    ++in_run;
    const fs::path summary = fs::path(out) / "summary.json";
    ASSERT_TRUE(fs::exists(summary)) << rep.error;
    std::ifstream f(summary);
    const auto j = nlohmann::json::parse(f, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << "summary.json is not whole";
    if (rep.error.find("in frame") != std::string::npos) {
      ASSERT_TRUE(j.contains("aborted"));
      EXPECT_NE(j["aborted"].get<std::string>().find("out of memory"), std::string::npos);
    }
    // the frames kept are whole files in an unbroken sequence, and the log is there
    int frames = 0;
    for (const auto& e : fs::directory_iterator(fs::path(out) / "frames")) {
      EXPECT_EQ(e.path().extension(), ".png") << e.path();
      ++frames;
    }
    EXPECT_EQ(frames, j["frames_written"].get<int>());
    EXPECT_TRUE(fs::exists(fs::path(out) / "haptic.csv") || fs::exists(fs::path(out) / "haptic.csv.partial"));
    // the session was finished: every tick the servo ran reached the log (a stop that left the queued ticks behind
    // keeps a log short of the run), and the summary counts the rows the file holds
    const fs::path csv = fs::exists(fs::path(out) / "haptic.csv") ? fs::path(out) / "haptic.csv"
                                                                  : fs::path(out) / "haptic.csv.partial";
    std::ifstream log(csv);
    int64_t rows = -1;  // (the header)
    for (std::string line; std::getline(log, line);) ++rows;
    EXPECT_EQ(rows, j["haptic_rows"].get<int64_t>()) << csv;
    EXPECT_EQ(rows, j["servo_ticks"].get<int64_t>()) << csv;
  }
  // most allocations of a recording are its frames': the sweep must have stopped some runs there
  EXPECT_GE(in_run, 3);
}

// A realtime run stopped by out of memory in its frame loop: the servo thread ran on while the frame failed, and the
// ticks it queued after the last frame took its samples reach haptic.csv all the same (the session is finished after
// the servo stops), so the log holds every tick the servo made and the summary says why the run ended.
TEST(OutOfMemory, ARealtimeRunStoppedInItsFrameLoopLogsEveryTickTheServoMade) {
  const Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  bool signalled = false;
  const ChildReport clean = run_child(scene, test::fresh_dir("oom_rt_clean"), 0, &signalled, true);
  ASSERT_FALSE(signalled);
  ASSERT_TRUE(clean.ok) << clean.error;
  ASSERT_GT(clean.allocations, 100);
  int in_frame = 0;
  for (int k = 3; k <= 7; k += 2) {
    // (a realtime run's allocations vary from run to run: a point in the middle lands in the frame loop)
    const long long at = clean.allocations * k / 10;
    const std::string out = test::fresh_dir("oom_rt_" + std::to_string(k));
    const ChildReport rep = run_child(scene, out, at, &signalled, true);
    SCOPED_TRACE("allocation " + std::to_string(at) + " of " + std::to_string(clean.allocations));
    ASSERT_FALSE(signalled) << "the recording aborted";
    if (rep.ok || rep.error.find("in frame") == std::string::npos) continue;
    ++in_frame;
    const auto j = nlohmann::json::parse(test::read_file(out + "/summary.json"), nullptr, false);
    ASSERT_TRUE(j.is_object()) << "no whole summary.json";
    EXPECT_NE(j.value("aborted", "").find("out of memory"), std::string::npos) << j.dump();
    std::ifstream log(fs::exists(fs::path(out) / "haptic.csv") ? fs::path(out) / "haptic.csv"
                                                               : fs::path(out) / "haptic.csv.partial");
    int64_t rows = -1;  // (the header)
    for (std::string line; std::getline(log, line);) ++rows;
    EXPECT_GT(rows, 0);
    EXPECT_EQ(rows, j["servo_ticks"].get<int64_t>()) << "ticks the servo made that never reached the log";
    EXPECT_EQ(rows, j["haptic_rows"].get<int64_t>());
  }
  std::printf("[ figures ] %d of 3 points stopped the realtime run in its frame loop\n", in_frame);
  EXPECT_GE(in_frame, 1) << "no point landed in the frame loop";
}

// With the recording's reserve alive, an allocation that fails where it cannot throw (a noexcept function, a
// destructor that allocates) is served from the reserve, and the reserve says so; a second failure throws.
TEST(OutOfMemory, AnAllocationThatFailsWhereItCannotThrowIsServedFromTheReserve) {
  const MemoryReserve reserve(std::size_t{1} << 20);
  EXPECT_FALSE(MemoryReserve::tripped());
  auto sized = []() noexcept { return std::vector<int>(1000).size(); };
  {
    test::AllocationFault fault(1);
    EXPECT_EQ(sized(), 1000u);
    EXPECT_TRUE(fault.fired());
  }
  EXPECT_TRUE(MemoryReserve::tripped());
  test::AllocationFault again(1);
  EXPECT_THROW(static_cast<void>(std::vector<int>(1000)), std::bad_alloc);
}

}  // namespace
}  // namespace palpate
