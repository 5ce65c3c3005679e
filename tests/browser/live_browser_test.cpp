// The live view in a real browser: `palpate record --serve` runs a realtime recording as a second process, headless
// Chromium opens its page, and the test reads what the page saw through the DevTools protocol (over a pipe): the
// picture on its canvas changes while the run goes on, the force plot has points, and the figures the page and
// /stats.json end on are those of summary.json.
#include <gtest/gtest.h>
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_run.h"
#include "support/http_get.h"
#include "support/fixtures.h"
#include "support/read_file.h"
#include "browser/chromium.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using test::read_file;
using test::Browser;
using test::spawn;

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in, nullptr, false);
}

// what the page saw, and a hash of the picture on its canvas
const char* kPageState = R"JS(JSON.stringify((() => {
  const c = document.getElementById("view");
  const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
  let h = 0;
  for (let i = 0; i < d.length; i += 4) h = (Math.imul(h, 31) + d[i] + 7 * d[i + 1] + 13 * d[i + 2]) >>> 0;
  return { drawn: live.framesDrawn, frame: live.lastFrame, force_points: live.forcePoints, finished: live.finished,
           hash: h, stats: live.stats };
})()))JS";

// A realtime recording the tool moves through all along: the cube pressed and released every second.
std::string moving_scene(const std::string& dir, double duration_s) {
  auto j = read_json(test::source_path("scenes/cube_press.json"));
  j["name"] = "cube_press_cycles";
  j["duration_s"] = duration_s;
  j["trajectory"] = nlohmann::json::array();
  for (int k = 0; k <= static_cast<int>(duration_s * 2) + 2; ++k)
    j["trajectory"].push_back({{"t_s", 0.5 * k}, {"pos_m", {0.004, 0.004, k % 2 == 0 ? 0.045 : 0.012}}});
  const std::string path = dir + "/cube_press_cycles.json";
  std::ofstream(path) << j.dump(2);
  return path;
}

TEST(LiveBrowser, PageShowsTheRecordingWhileItRunsAndEndsOnItsSummary) {
  ASSERT_EQ(test::shell("command -v chromium").code, 0)
      << "chromium is not installed: the browser test needs it (scripts/install_deps.sh installs it)";
  const std::string dir = test::fresh_dir("live_browser");
  fs::create_directories(dir);
  const std::string out = dir + "/rec";
  const std::string scene = moving_scene(dir, 10.0);
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  const std::string palpate = std::string(bin ? bin : "build/bin") + "/palpate";
  const std::string log = dir + "/record.log";
  const pid_t rec = spawn({palpate, "record", scene, "--mode", "realtime", "--serve", "127.0.0.1:0", "--serve-linger",
                           "120", "--no-video", "--quiet", "--out", out},
                          log);
  ASSERT_GT(rec, 0);
  struct Reap {
    pid_t pid;
    ~Reap() {
      if (pid > 0 && ::waitpid(pid, nullptr, WNOHANG) == 0) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, nullptr, 0);
      }
    }
  } reap{rec};

  // the URL is printed on stderr at start
  std::string url;
  for (auto end = Clock::now() + std::chrono::seconds(60); url.empty() && Clock::now() < end;) {
    const std::string text = read_file(log);
    const auto at = text.find("live view at http://127.0.0.1:");
    if (at != std::string::npos) url = text.substr(at + 13, text.find('\n', at) - at - 13);
    else std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_FALSE(url.empty()) << read_file(log);
  const int port = std::stoi(url.substr(url.rfind(':') + 1));

  Browser browser;
  ASSERT_TRUE(browser.launch(url, dir));
  ASSERT_TRUE(browser.attach(url)) << read_file(dir + "/chromium.log");

  // watch the page until it says the recording finished
  std::set<uint32_t> hashes_while_running;
  int64_t first_frame = -1, last_frame_running = -1;
  nlohmann::json state;
  for (auto end = Clock::now() + std::chrono::seconds(180); Clock::now() < end;) {
    const auto v = browser.eval(kPageState);
    if (v.is_string()) {
      state = nlohmann::json::parse(v.get<std::string>(), nullptr, false);
      if (state.is_object() && state["finished"].get<bool>()) break;
      if (state.is_object() && state["drawn"].get<int64_t>() > 0) {
        hashes_while_running.insert(state["hash"].get<uint32_t>());
        if (first_frame < 0) first_frame = state["frame"].get<int64_t>();
        last_frame_running = state["frame"].get<int64_t>();
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  ASSERT_TRUE(state.is_object() && state["finished"].get<bool>()) << state.dump() << "\n" << read_file(log);

  // the picture changed while the run went on, from frames received one after another
  EXPECT_GE(hashes_while_running.size(), 2u) << "the canvas showed one picture only";
  EXPECT_GT(last_frame_running, first_frame);
  EXPECT_GE(state["drawn"].get<int64_t>(), 3) << state.dump();
  // the force plot has points
  EXPECT_GT(state["force_points"].get<int64_t>(), 0) << state.dump();

  // the figures the page and /stats.json end on are those of summary.json
  const auto summary = read_json(out + "/summary.json");
  ASSERT_FALSE(summary.is_discarded());
  const auto stats = nlohmann::json::parse(test::http_get_body(port, "/stats.json"), nullptr, false);
  ASSERT_TRUE(stats.is_object());
  for (const auto& shown : {stats, state["stats"]}) {
    EXPECT_TRUE(shown["finished"].get<bool>());
    EXPECT_EQ(shown["frames_written"], summary["frames_written"]);
    EXPECT_EQ(shown["frames_dropped"], summary["frames_dropped"]);
    EXPECT_EQ(shown["frames_late"], summary["sim"]["frames_late"]);
    EXPECT_EQ(shown["servo"]["ticks"], summary["servo_ticks"]);
    EXPECT_EQ(shown["servo"]["overruns"], summary["servo"]["overruns"]);
    EXPECT_EQ(shown["servo"]["p50_us"], summary["servo"]["latency_us"]["p50"]);
    EXPECT_EQ(shown["servo"]["p99_us"], summary["servo"]["latency_us"]["p99"]);
    EXPECT_EQ(shown["max_force_N"], summary["max_force_N"]);
  }
  EXPECT_EQ(summary["frames_written"].get<int64_t>(), static_cast<int64_t>(std::distance(
      fs::directory_iterator(out + "/frames"), fs::directory_iterator{})));

  // the lingering server ends on SIGTERM, and the recording's exit status is a success
  ::kill(rec, SIGTERM);
  int status = 0;
  ASSERT_EQ(::waitpid(rec, &status, 0), rec);
  reap.pid = -1;
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_file(log);
}

}  // namespace
}  // namespace palpate
