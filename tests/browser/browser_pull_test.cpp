// A person's pull through the browser: headless Chromium grabs the bunny's back in pull mode (Space and a left drag)
// and shakes it sideways at 0.5, 1, 2 and 5 Hz, as a hand does, then holds still. The coupling stays passive (the
// device never gives the hand more energy than the hand put in), the pull settles when the hand stops (no growing or
// sustained oscillation), and the realtime session replays in lockstep tick for tick (haptic.csv's frame and
// model_frame: the order its ticks and frames ran), so `bench feel --device replay:` judges the session itself.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "browser/browser_page.h"
#include "browser/chromium.h"
#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/read_file.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;
using test::Browser;
using test::log_rows;
using test::Clock;
using test::read_file;
using test::Recording;

constexpr int kTick = 0, kTool = 2, kProxy = 5, kForce = 8, kContact = 11;

// One person's pull on `scene`: Chromium grabs, shakes, holds still; the session is judged and replayed.
// max_buzz: the share of the replay's force above 100 Hz it may have; max_excess_N: the largest step beyond what the
// hand's own motion explains (bench feel's figures; <= 0: not judged).
void person_pull(const std::string& scene, const std::string& tag, double max_buzz, double max_excess_N) {
  ASSERT_EQ(test::shell("command -v chromium").code, 0)
      << "chromium is not installed: the browser test needs it (scripts/install_deps.sh installs it)";
  const std::string dir = test::fresh_dir("browser_person_pull_" + tag);
  fs::create_directories(dir);
  Browser browser;
  ASSERT_TRUE(browser.launch("about:blank", dir));
  ASSERT_TRUE(browser.attach("about:blank")) << read_file(dir + "/chromium.log");
  Recording rec(dir, scene, 16.0);
  ASSERT_FALSE(rec.url.empty()) << read_file(rec.log);
  browser.call("Page.navigate", {{"url", rec.url}}, true);
  for (int i = 0; i < 100 && browser.eval("location.href") != rec.url; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_EQ(test::role(browser), "control");
  const auto rect = test::overlay_rect(browser);
  ASSERT_EQ(rect.size(), 4u);
  double y = 0.0;
  ASSERT_TRUE(test::grab_bunny(browser, rect, rec, &y).is_object()) << "Space never grabbed the bunny" << read_file(rec.log);

  // sideways shakes of 0.08 of the view's half width (about 5 mm), a mouse event every 16 ms as a pointer gives
  const double amp = 0.08;
  for (const auto& [hz, cycles] : {std::pair{0.5, 1}, {1.0, 2}, {2.0, 3}, {5.0, 5}}) {
    const auto t0 = Clock::now();
    for (double t = 0.0; t < cycles / hz && rec.pid > 0; t = std::chrono::duration<double>(Clock::now() - t0).count()) {
      test::mouse(browser, rect, "mouseMoved", amp * std::sin(2.0 * std::numbers::pi * hz * t), y, true);
      std::this_thread::sleep_for(std::chrono::milliseconds(16));
    }
  }
  test::mouse(browser, rect, "mouseMoved", 0.0, y, true);
  // then still, Space and the button held: the tick the hand stopped at
  const auto st = rec.stats();
  ASSERT_TRUE(st.is_object()) << read_file(rec.log);
  const int64_t still_from = st["servo"]["ticks"].get<int64_t>();
  ASSERT_EQ(rec.wait(40), 0) << read_file(rec.log);
  test::space(browser, false);
  test::mouse(browser, rect, "mouseReleased", 0.0, y, false);

  const auto live = log_rows(rec.out + "/haptic.csv");
  ASSERT_GT(live.size(), 10000u);
  // the work the device did on the hand, summed from the start: a passive coupling never gives back more than the
  // hand put in (the lattice and the coupling spring only store it) and what the grab itself stored — it takes a
  // surface point up to grab_radius_m from the tool, a coupling spring stretched that far (1/2 k d^2)
  const double k_N_per_m =
      nlohmann::json::parse(read_file(rec.out + "/summary.json"))["coupling"]["stiffness_N_per_m"].get<double>();
  double work_J = 0.0, most_J = 0.0, grab_J = 0.0;
  int64_t grab = 0;
  for (std::size_t i = 0; i + 1 < live.size(); ++i) {
    for (int k = 0; k < 3; ++k) work_J += live[i][kForce + k] * (live[i + 1][kTool + k] - live[i][kTool + k]);
    most_J = std::max(most_J, work_J);
    if (live[i][kContact] == 2 && (i == 0 || live[i - 1][kContact] != 2)) {
      const double d = std::hypot(live[i][kProxy] - live[i][kTool], live[i][kProxy + 1] - live[i][kTool + 1],
                                  live[i][kProxy + 2] - live[i][kTool + 2]);
      grab_J += 0.5 * k_N_per_m * d * d;
    }
    grab += live[i][kContact] == 2;
  }
  // once the hand is still (from 0.5 s after it stopped to the end): the pull settles, no oscillation of its own; and
  // what swing is left does not grow (the force's range over the still time's second half within its first half's)
  double lo = 1e9, hi = -1e9;
  int64_t still_rows = 0;
  std::vector<double> still_N;
  for (const auto& r : live) {
    if (r[kTick] < static_cast<double>(still_from + 500) || r[kContact] != 2) continue;
    const double f = std::hypot(r[kForce], r[kForce + 1], r[kForce + 2]);
    lo = std::min(lo, f);
    hi = std::max(hi, f);
    still_N.push_back(f);
    ++still_rows;
  }
  const auto half = static_cast<std::ptrdiff_t>(still_N.size() / 2);
  const auto range = [](auto a, auto b) { return a == b ? 0.0 : *std::max_element(a, b) - *std::min_element(a, b); };
  const double first_N = range(still_N.begin(), still_N.begin() + half), last_N = range(still_N.begin() + half, still_N.end());
  std::printf("[ figures ] %s: %zu ticks, %lld grabbed; work the device did on the hand: at most %.4f mJ (the grabs stored "
              "%.4f mJ), at the end %.4f mJ; still hand (%lld ticks): force %.3f..%.3f N (range %.3f N, then %.3f N)\n",
              scene.c_str(), live.size(), static_cast<long long>(grab), most_J * 1e3, grab_J * 1e3, work_J * 1e3,
              static_cast<long long>(still_rows), lo, hi, first_N, last_N);
  EXPECT_GT(grab, 3000) << "the grab did not hold through the shakes";
  EXPECT_LE(most_J, grab_J + 0.1e-3) << "the device gave the hand energy it never put in";
  ASSERT_GT(still_rows, 500) << "the grab did not hold while the hand was still";
  EXPECT_LE(hi - lo, 0.05) << "the pull kept swinging with the hand still";
  EXPECT_LE(last_N, first_N + 0.005) << "the swing grew with the hand still: " << first_N << " N, then " << last_N << " N";

  // replayed in lockstep, the session tick for tick
  const std::string replay = dir + "/replay";
  const auto r = test::shell(test::palpate_bin() + " record " + test::source_path(scene) +
                             " --device replay:" + rec.out + " --no-render -q --out " + replay);
  ASSERT_EQ(r.code, 0) << r.out;
  const auto again = log_rows(replay + "/haptic.csv");
  ASSERT_EQ(again.size(), live.size());
  double worst_N = 0.0;
  for (std::size_t i = 0; i < live.size(); ++i) {
    ASSERT_EQ(again[i][kTick], live[i][kTick]) << "row " << i;
    for (int k = 0; k < 3; ++k) worst_N = std::max(worst_N, std::abs(again[i][kForce + k] - live[i][kForce + k]));
  }
  std::printf("[ figures ] replay: largest force difference from the session %.3g N over %zu ticks\n", worst_N,
              live.size());
  EXPECT_LE(worst_N, 0.02);
  // and bench feel of the replay judges those ticks: as many, and as many in contact
  const std::string json = dir + "/feel.json";
  const auto b = test::shell(test::palpate_bin() + " bench feel " + test::source_path(scene) +
                             " --device replay:" + rec.out + " --json " + json);
  ASSERT_EQ(b.code, 0) << b.out;
  const auto feel = nlohmann::json::parse(read_file(json))["scenes"][0];
  int64_t contact = 0;
  for (const auto& row : live) contact += row[kContact] != 0;
  EXPECT_EQ(feel["ticks"].get<int64_t>(), static_cast<int64_t>(live.size()));
  EXPECT_EQ(feel["contact_ticks"].get<int64_t>(), contact);
  // and what it judges has no more buzz than max_buzz
  std::printf("[ figures ] bench feel of the replay: %.2f %% of the force above 100 Hz\n",
              100.0 * feel["buzz_share_above_hz"]["share"].get<double>());
  EXPECT_LT(feel["buzz_share_above_hz"]["share"].get<double>(), max_buzz) << feel.dump();
  // and no click beyond max_excess_N
  std::printf("[ figures ] bench feel of the replay: largest step beyond the hand's motion %.3f N\n",
              feel["steady"]["max_excess_N"].get<double>());
  if (max_excess_N > 0.0) {
    EXPECT_LT(feel["steady"]["max_excess_N"].get<double>(), max_excess_N) << feel.dump();
  }
}

// The demo bunny_pull, a gel of E 10 kPa stepped implicitly: a grab takes the local model's prediction between frames
// (without it the held point and the coupling traded the pull frame by frame and swung up: 7.6 J given to the hand).
TEST(BrowserPull, APersonShakingTheGelBunnysGrabStaysPassiveSettlesAndReplaysTickForTick) {
  // (with the prediction dropped for a frame's first ticks, when the held point on the blended surface was judged a
  // cell from the new frame's contact: 1.9-7.3 % of its force above 100 Hz, 2.3 N steps at 60 Hz)
  // (and steps of 2.3 N at 60 Hz)
  person_pull("scenes/bunny_pull.json", "gel", 0.01, 0.2);
}

// The paper's spring bunny, stepped explicitly: a grab holds the frame's surface (the static prediction put the held
// point 10 mm off for a few ticks each frame: steps of 2-4 N, 11.8-18.9 mJ given to the hand).
TEST(BrowserPull, APersonShakingTheSpringBunnysGrabStaysPassiveSettlesAndReplaysTickForTick) {
  // (the swinging pull, predicted between frames: 7.6 % of its force above 100 Hz)
  // (single steps of 0.2-0.52 N beyond the hand's motion, in some runs: a realtime frame that came before the last
  // one's blend was done made the held point jump the rest of that way at once; the servo now goes on from where the
  // surface is, and six runs gave 0.032-0.051 N)
  person_pull("scenes/bunny_pull_springs.json", "springs", 0.01, 0.2);
}

}  // namespace
}  // namespace palpate
