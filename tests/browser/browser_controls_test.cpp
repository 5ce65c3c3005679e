// The page's controls end to end (docs/browser-device.md, "The page's controls"): `palpate record --device browser
// --serve` as a second process and headless Chromium clicking the page's own controls as a person does. On the bunny
// with a sphere tool: the stiffness at the top of its range makes the surface give less from the first touch to 0.6 N, a larger
// tool radius meets the surface higher, pull mode grabs with Space and pulls the hand back, a reset puts the tool back
// where it waited with no force; every change is counted, listed in summary.json, and the run replays within 0.02 N a
// tick.
#include <gtest/gtest.h>

#include <signal.h>

#include <cmath>
#include <filesystem>
#include <fstream>
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
using test::norm;
using test::read_file;
using test::Recording;
using test::stats_until;

// Clicks the page's element `id` at `frac` of its width (a range input takes the value there), as a mouse does.
void click(Browser& b, const std::string& id, double frac = 0.5) {
  const auto r = b.eval("(() => { const r = document.getElementById('" + id +
                        "').getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; })()");
  ASSERT_TRUE(r.is_array() && r.size() == 4u) << id;
  const double x = r[0].get<double>() + std::clamp(frac * r[2].get<double>(), 1.0, r[2].get<double>() - 1.0);
  const double y = r[1].get<double>() + r[3].get<double>() / 2;
  for (const char* type : {"mousePressed", "mouseReleased"})
    b.call("Input.dispatchMouseEvent",
           {{"type", type}, {"x", x}, {"y", y}, {"button", "left"}, {"buttons", type[5] == 'P' ? 1 : 0}, {"clickCount", 1}},
           true);
}

// A press from above down onto the bunny's back (from 0.8 of the view's height, at view depth `depth`): the handle's height when the force first passes
// 0.1 N (the touch) and 0.6 N; the mouse let go after.
struct Press {
  double touch_z = NAN, firm_z = NAN;
};
Press press(Browser& b, const std::vector<double>& rect, const Recording& rec, double depth) {
  Press p;
  // (the tool waits where the scene starts after a change of the controls: a loaded machine's page may need another
  // round of drags to bring it to the top of the view)
  bool there = false;
  for (int k = 0; k < 3 && !there; ++k) there = test::tool_to(b, rect, 0.0, 0.8, depth);
  // (a little short of 0.8, or a wheel notch off in depth, is fine while over the bunny's back: the press goes down
  // from there)
  const auto hv = test::tool_view(b);
  if (!there && (hv.size() != 3 || hv[1] < 0.6 || std::abs(hv[0]) > 0.05 || std::abs(hv[2] - depth) > 0.3)) {
    std::printf("the tool did not come over the bunny: %s\n", b.eval("live.device.hv").dump().c_str());
    return p;
  }
  test::mouse(b, rect, "mousePressed", 0.0, 0.8, true);
  double y = 0.8;
  for (; y > -0.6 && std::isnan(p.firm_z); y -= 0.005) {
    test::mouse(b, rect, "mouseMoved", 0.0, y, true);
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
    const auto s = rec.stats();
    if (!s.is_object() || !s.contains("browser")) continue;
    const double f = norm(s["browser"]["force_N"]), z = s["browser"]["handle_m"][2].get<double>();
    if (f > 0.1 && std::isnan(p.touch_z)) p.touch_z = z;
    if (f > 0.6) p.firm_z = z;
  }
  test::mouse(b, rect, "mouseReleased", 0.0, y, false);
  return p;
}

// waits for the controls numbered `seq` to be in force and the force gone; those stats
nlohmann::json changed_to(const Recording& rec, int64_t seq) {
  return stats_until(rec, 10.0, [seq](const nlohmann::json& j) {
    return j["browser"]["controls"]["seq"] == seq && norm(j["browser"]["force_N"]) == 0.0;
  });
}

// haptic.csv's columns: the proxy's z, the force, the controls' number
constexpr int kControls = 17;

TEST(BrowserControls, EachControlOnThePageChangesWhatTheServoDoesAndTheRunReplaysThem) {
  ASSERT_EQ(test::shell("command -v chromium").code, 0)
      << "chromium is not installed: the browser test needs it (scripts/install_deps.sh installs it)";
  const std::string dir = test::fresh_dir("browser_controls");
  fs::create_directories(dir);
  // the demo bunny with a 2 mm sphere tool (its own scene's point tool has a radius that is only drawn)
  auto scene = nlohmann::json::parse(read_file(test::source_path("scenes/bunny_touch.json")));
  scene["mesh"]["file"] = test::source_path("scenes/bunny.obj");
  scene["device"]["tool_shape"] = "sphere";
  const std::string scene_path = dir + "/bunny_sphere.json";
  std::ofstream(scene_path) << scene.dump(2);
  Recording rec(dir, scene_path, 300.0);
  Browser browser;
  ASSERT_EQ(test::steer_page(browser, rec, dir), "");
  const auto rect = test::overlay_rect(browser);
  ASSERT_EQ(rect.size(), 4u);

  // the page shows the scene's bounds: touch and pull (a volumetric material is not cut), E 30 kPa x 0.25..4, a
  // radius of 1..4 mm
  const auto limits = browser.eval("live.device.limits");
  ASSERT_TRUE(limits.is_object()) << limits.dump();
  EXPECT_EQ(limits["modes"], nlohmann::json({"touch", "pull"}));
  EXPECT_EQ(limits["stiffness"], nlohmann::json({0.25, 4.0}));
  EXPECT_NEAR(limits["radius_mm"][0].get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(limits["radius_mm"][1].get<double>(), 4.0, 1e-9);
  EXPECT_NEAR(limits["young_modulus_kPa"].get<double>(), 30.0, 1e-9);
  EXPECT_EQ(browser.eval("getComputedStyle(document.getElementById('controls')).display"), "block");
  const auto start = rec.stats()["browser"]["handle_m"];
  const double depth0 = 0.0;  // the plane through the bunny's middle

  const Press soft = press(browser, rect, rec, depth0);
  ASSERT_FALSE(std::isnan(soft.firm_z)) << "the press never reached 0.6 N: " << rec.stats()["browser"].dump();

  // the stiffness slider to its top: the model starts again, four times as stiff; the tool is back where it waited
  click(browser, "stiff", 1.0);
  nlohmann::json s = changed_to(rec, 1);
  ASSERT_EQ(s["browser"]["controls"]["seq"], 1) << s["browser"].dump();
  EXPECT_NEAR(s["browser"]["controls"]["stiffness"].get<double>(), 4.0, 0.05);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s["browser"]["handle_m"][k].get<double>(), start[k].get<double>(), 1e-9);
  EXPECT_FALSE(s["browser"]["engaged"].get<bool>());
  const Press stiff = press(browser, rect, rec, depth0);
  ASSERT_FALSE(std::isnan(stiff.firm_z));

  // the radius slider to its top (4 mm): the sphere meets the bunny's back higher by about the 2 mm it grew
  click(browser, "radius", 1.0);
  s = changed_to(rec, 2);
  ASSERT_EQ(s["browser"]["controls"]["seq"], 2) << s["browser"].dump();
  EXPECT_NEAR(s["browser"]["controls"]["radius_mm"].get<double>(), 4.0, 0.05);
  const Press big = press(browser, rect, rec, depth0);
  ASSERT_FALSE(std::isnan(big.touch_z)) << rec.stats()["browser"].dump();
  std::printf("[ figures ] the 4 mm sphere touched %.2f mm higher than the 2 mm one\n", 1e3 * (big.touch_z - stiff.touch_z));
  EXPECT_GT(big.touch_z - stiff.touch_z, 0.001);
  EXPECT_LT(big.touch_z - stiff.touch_z, 0.003);

  // pull: Space grabs the back, and lifting the tool pulls the hand down (a touch gives nothing above the surface)
  click(browser, "mode-pull");
  s = changed_to(rec, 3);
  ASSERT_EQ(s["browser"]["controls"]["mode"], "pull") << s["browser"].dump();
  double y = 0.0;
  const auto grabbed = test::grab_bunny(browser, rect, rec, &y);
  ASSERT_TRUE(grabbed.is_object()) << "never grabbed: " << rec.stats()["browser"].dump();
  double pull_N = 0.0;
  for (int i = 1; i <= 30 && pull_N > -0.2; ++i) {
    test::mouse(browser, rect, "mouseMoved", 0.0, y + 0.004 * i, true);
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    pull_N = std::min(pull_N, rec.stats()["browser"]["force_N"][2].get<double>());
  }
  EXPECT_LT(pull_N, -0.2) << "lifting the grab did not pull the hand back down";
  test::space(browser, false);
  test::mouse(browser, rect, "mouseReleased", 0.0, y, false);

  // reset: the tool back where it waited, no force, the model at rest
  click(browser, "reset");
  s = changed_to(rec, 4);
  ASSERT_EQ(s["browser"]["controls"]["resets"], 1) << s["browser"].dump();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(s["browser"]["handle_m"][k].get<double>(), start[k].get<double>(), 1e-9);
  EXPECT_EQ(s["browser"]["controls"]["changes"], 4);
  EXPECT_EQ(s["browser"]["controls"]["refused"], 0);
  const auto quiet = test::quiet_for(rec, 1.0, 0.2);
  EXPECT_EQ(quiet.max_N, 0.0);

  // a crafted change out of the scene's bounds is refused with why, and changes nothing
  EXPECT_TRUE(browser.eval("(() => { sock.send('c cut 1 2'); return true; })()").get<bool>());
  s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["controls"]["refused"] == 1; });
  EXPECT_NE(s["browser"]["controls"]["last_refusal"].get<std::string>().find("mode 'cut'"), std::string::npos);
  EXPECT_EQ(s["browser"]["controls"]["seq"], 4);

  // Ctrl-C: the run keeps its outputs and lists the changes
  ::kill(rec.pid, SIGINT);
  EXPECT_EQ(rec.wait(60), 130) << read_file(rec.log);
  const auto summary = nlohmann::json::parse(read_file(rec.out + "/summary.json"));
  ASSERT_EQ(summary["controls"].size(), 4u) << summary.dump();
  EXPECT_EQ(summary["controls"][2]["mode"], "pull");
  EXPECT_EQ(summary["controls"][3]["resets"], 1);

  // replayed in lockstep, the session tick for tick (the changes at the same ticks)
  const std::string replay = dir + "/replay";
  const auto r = test::shell(test::palpate_bin() + " record " + scene_path + " --device replay:" + rec.out +
                             " --no-render -q --out " + replay);
  ASSERT_EQ(r.code, 0) << r.out;
  const auto live = log_rows(rec.out + "/haptic.csv"), again = log_rows(replay + "/haptic.csv");
  // the stiffness from the log: how far the surface under the tool gave (the proxy's fall) from the first 0.1 N to
  // the first 0.6 N of the press under the scene's controls (seq 0) and under the stiffest (seq 1)
  // (a segment begins with the force of the press before going, at the jump limit: the press is after it)
  auto give_mm = [&](int64_t seq) -> double {
    double z01 = NAN;
    bool let_go = false;
    for (const auto& row : live) {
      if (static_cast<int64_t>(row[kControls]) != seq) continue;
      const double f = std::hypot(row[8], row[9], row[10]);
      if (!(let_go = let_go || f < 0.05)) continue;
      if (f > 0.1 && std::isnan(z01)) z01 = row[7];
      if (f > 0.6) return 1e3 * (z01 - row[7]);
    }
    return NAN;
  };
  const double soft_mm = give_mm(0), stiff_mm = give_mm(1);
  std::printf("[ figures ] from 0.1 N to 0.6 N the surface gave %.2f mm at E 30 kPa, %.2f mm at E 120 kPa\n", soft_mm,
              stiff_mm);
  EXPECT_LT(stiff_mm, 0.5 * soft_mm);
  EXPECT_GT(stiff_mm, 0.0);
  ASSERT_EQ(again.size(), live.size());
  double worst_N = 0.0;
  for (std::size_t i = 0; i < live.size(); ++i)
    for (int k = 8; k < 11; ++k) worst_N = std::max(worst_N, std::abs(again[i][k] - live[i][k]));
  std::printf("[ figures ] replay: largest force difference from the session %.3g N over %zu ticks\n", worst_N,
              live.size());
  EXPECT_LE(worst_N, 0.02);
  const auto replayed = nlohmann::json::parse(read_file(replay + "/summary.json"));
  ASSERT_EQ(replayed["controls"].size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(replayed["controls"][k]["frame"], summary["controls"][k]["frame"]);
}

}  // namespace
}  // namespace palpate
