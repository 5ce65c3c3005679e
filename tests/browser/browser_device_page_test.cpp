// --device browser end to end: `palpate record --device browser --serve` as a second process. Headless Chromium opens
// the page and steers the tool with synthetic mouse and key events (DevTools Input): a drag onto the bunny makes
// contact, a force in /stats.json and a dent in the recorded frames; a second page only watches; closing the steering
// page mid-press fades the force to zero within the watchdog. Space held while dragging grabs and pulls in pull mode;
// a right drag lowers the blade and cuts in cut mode. A recording made through the socket replays (--device replay:)
// along the same path.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "browser/browser_page.h"
#include "browser/chromium.h"
#include "browser/frame_pixels.h"
#include "haptics/devices/browser_device.h"
#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/http_get.h"
#include "support/read_file.h"
#include "support/ws_client.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;
using test::Browser;
using test::Clock;
using test::read_file;
using test::Recording;
using test::mouse;
using test::norm;
using test::overlay_rect;
using test::press_onto_bunny;
using test::role;
using test::space;
using test::stats_until;
using test::tool_to;
using test::palpate_bin;

TEST(BrowserDevice, PageSteersTheToolOntoTheBunnyASecondPageWatchesClosingFadesTheForce) {
  ASSERT_EQ(test::shell("command -v chromium").code, 0)
      << "chromium is not installed: the browser test needs it (scripts/install_deps.sh installs it)";
  const std::string dir = test::fresh_dir("browser_device");
  fs::create_directories(dir);
  Recording rec(dir, "scenes/bunny_touch.json", 120.0);
  Browser browser;
  ASSERT_EQ(test::steer_page(browser, rec, dir), "");
  const std::string first_target = browser.target();
  const auto rect = overlay_rect(browser);
  ASSERT_EQ(rect.size(), 4u);

  {
    // connected, no input yet: the tool waits at the scene's first key, no force, nothing engaged, nothing sent
    stats_until(rec, 30.0, [](const nlohmann::json& j) { return j["servo"]["ticks"].get<int64_t>() > 500; });
    const auto idle = rec.stats()["browser"];
    const std::vector<double> first_key{0.015, -0.01, 0.04};  // scenes/bunny_touch.json, trajectory[0]
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(idle["handle_m"][k].get<double>(), first_key[static_cast<std::size_t>(k)], 1e-9);
    EXPECT_EQ(norm(idle["force_N"]), 0.0);
    EXPECT_FALSE(idle["engaged"].get<bool>());
    EXPECT_EQ(idle["messages"], 0) << "the page sent poses before any input";
  }
  // input is relative: the tool to the top of the view in the plane through the bunny's middle, then straight down
  // onto its back until the force passes 0.4 N; then held
  EXPECT_GT(press_onto_bunny(browser, rect, rec, 0.4), 0.3) << browser.eval("live.device.hv").dump();
  nlohmann::json s = rec.stats();
  ASSERT_TRUE(s.is_object() && s.contains("browser")) << read_file(rec.log);
  s = stats_until(rec, 2.0, [](const nlohmann::json& j) { return norm(j["browser"]["force_N"]) > 0.3; });
  const double pressed_N = norm(s["browser"]["force_N"]);
  EXPECT_GT(pressed_N, 0.3) << s["browser"].dump();
  EXPECT_GT(s["max_force_N"].get<double>(), 0.3);
  EXPECT_TRUE(s["browser"]["controlled"].get<bool>());
  EXPECT_GT(s["browser"]["messages"].get<int64_t>(), 30);
  // the page measured its input-to-force latency and reported it
  s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["page_input_to_force_ms"]["n"] > 0; });
  EXPECT_GT(s["browser"]["page_input_to_force_ms"]["n"].get<int>(), 0) << s["browser"].dump();
  EXPECT_GT(s["browser"]["input_to_force_us"]["n"].get<int>(), 0) << s["browser"].dump();
  const auto handle = s["browser"]["handle_m"];

  // the dent in the frames: a frame rendered during the press against the run's first (rendered before the page
  // connected: the surface at rest), around where the tool touches (the handle where the camera sees it, as the page
  // draws it): the surface itself moved there
  const auto hv = browser.eval("live.device.hs");
  const std::string before_png = rec.out + "/frames/" + test::first_frame_name(rec.out + "/frames");
  const std::string pressed_png = test::newest_frame_after(rec.out + "/frames", 3);
  ASSERT_TRUE(hv.is_array() && hv.size() == 2 && !pressed_png.empty()) << hv.dump();
  const auto before_read = read_png(before_png), pressed_read = read_png(pressed_png);
  ASSERT_TRUE(before_read.ok() && pressed_read.ok()) << before_png << " " << pressed_png;
  const Image& before = before_read.value();
  const Image& pressed = pressed_read.value();
  const int tx = static_cast<int>((hv[0].get<double>() + 1) / 2 * before.width);
  const int ty = static_cast<int>((1 - hv[1].get<double>()) / 2 * before.height);
  // around the tool (40 px: the lattice's 7 cells span about 60 px on this view) most of the surface moved; 110 px
  // below it, on the bunny's body beyond the lattice, nothing did
  const auto [dent_surface, dent_px] = test::surface_pixels_moved(before, pressed, tx, ty, 40);
  const auto [far_surface, far_px] = test::surface_pixels_moved(before, pressed, tx, ty + 110, 40);
  EXPECT_GT(dent_px, 300) << "the surface did not move around the tool at (" << tx << ", " << ty << ") between "
                          << before_png << " and " << pressed_png << " (" << dent_surface << " surface pixels)";
  EXPECT_GT(far_surface, 3000) << "the window below the tool is not on the bunny";
  EXPECT_EQ(far_px, 0) << "the surface moved far from the tool";

  // a second page watches: the server tells it so, and its pointer messages (far to the right) move nothing. (It
  // speaks the page's protocol directly: a second Chromium window would push the first into the background, where
  // the browser throttles its timers and the device rightly fades out.)
  test::WsClient second;
  ASSERT_EQ(second.open(rec.port, "/ws").rfind("HTTP/1.1 101", 0), 0u);
  EXPECT_NE(second.read().payload.find("\"role\":\"watch\""), std::string::npos);
  for (int i = 1; i <= 20; ++i) {
    ASSERT_TRUE(second.send_text("p " + std::to_string(i) + " 0.9 0.9 0 1"));
    std::this_thread::sleep_for(std::chrono::milliseconds(15));
  }
  s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["ignored"] >= 20; });
  EXPECT_EQ(s["browser"]["pages"], 2);
  EXPECT_EQ(s["browser"]["ignored"], 20) << s["browser"].dump();
  const auto moved = s["browser"]["handle_m"];
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(moved[k].get<double>(), handle[k].get<double>(), 0.002) << s["browser"].dump();
  EXPECT_GT(norm(s["browser"]["force_N"]), 0.2);
  EXPECT_EQ(s["browser"]["force_scale"], 1.0) << "the steering page is still live";
  second.close_socket();

  // the steering page closes mid-press: the force fades to zero within the watchdog
  s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["pages"] == 1; });
  ASSERT_GT(norm(s["browser"]["force_N"]), 0.2) << "still pressing before the close: " << s["browser"].dump();
  const nlohmann::json lat = s["browser"];
  browser.call("Target.closeTarget", {{"targetId", first_target}}, false);
  const auto closed = Clock::now();
  s = stats_until(rec, 5.0, [](const nlohmann::json& j) {
    return j["browser"]["pages"] == 0 && norm(j["browser"]["force_N"]) == 0.0;
  });
  const double to_zero_s = std::chrono::duration<double>(Clock::now() - closed).count();
  EXPECT_EQ(norm(s["browser"]["force_N"]), 0.0) << s["browser"].dump();
  EXPECT_EQ(s["browser"]["force_scale"], 0.0);
  // the bound is the watchdog plus the close reaching the server and the polling (generous on a busy machine)
  EXPECT_LT(to_zero_s, BrowserParams{}.watchdog_s() + 2.0);
  std::printf("[ figures ] pressed %.2f N; surface pixels moved within 40 px of the tool %d of %d (110 px below: %d of %d); force zero "
              "%.0f ms after the page closed (watchdog %.0f ms)\n",
              pressed_N, dent_px, dent_surface, far_px, far_surface, to_zero_s * 1e3, BrowserParams{}.watchdog_s() * 1e3);
  auto p = [&lat](const char* k, double scale) {
    const auto& v = lat[k];
    return v.value("n", 0) > 0 ? std::to_string(v["p50"].get<double>() * scale).substr(0, 6) + " / " +
                                     std::to_string(v["p99"].get<double>() * scale).substr(0, 6) + " ms (n " +
                                     std::to_string(v["n"].get<int>()) + ")"
                               : std::string("none");
  };
  std::printf("[ figures ] p50 / p99: server receipt -> force %s; page input -> force back %s; page input -> frame %s\n",
              p("input_to_force_us", 1e-3).c_str(), p("page_input_to_force_ms", 1.0).c_str(),
              p("page_input_to_frame_ms", 1.0).c_str());
}


// haptic.csv's tool columns (t_s and tool position) as text, row by row
std::vector<std::string> tool_path(const std::string& csv) {
  std::istringstream in(read_file(csv));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  for (std::stringstream h(line); std::getline(h, line, ',');) names.push_back(line);
  std::vector<int> cols;
  for (const char* want : {"t_s", "tool_x_m", "tool_y_m", "tool_z_m", "buttons"})
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == want) cols.push_back(static_cast<int>(i));
  std::vector<std::string> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    for (std::stringstream r(line); std::getline(r, line, ',');) f.push_back(line);
    std::string row;
    for (int c : cols) row += f[static_cast<std::size_t>(c)] + ",";
    rows.push_back(row);
  }
  return rows;
}

std::string hash_of(const std::string& dir) {
  return nlohmann::json::parse(read_file(dir + "/summary.json"))["state_hash"].get<std::string>();
}

// haptic.csv's rows whose contact column is `state` (2 grab, 3 cut), and the largest force among them
std::pair<int, double> rows_in_state(const std::string& csv, int state) {
  std::istringstream in(read_file(csv));
  std::string line;
  std::getline(in, line);
  int rows = 0;
  double max_N = 0.0;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::istringstream cells(line);
    for (std::string c; std::getline(cells, c, ',');) v.push_back(std::atof(c.c_str()));
    if (v.size() < 12 || static_cast<int>(v[11]) != state) continue;
    ++rows;
    max_N = std::max(max_N, std::hypot(v[8], v[9], v[10]));
  }
  return {rows, max_N};
}

// Pull and cut as a person with a mouse does them, in one headless Chromium (DevTools Input events into the page).
// Pull: a left drag down onto the bunny's back, Space pressed and let go on the way until a press holds the surface
// (a force), then held while the drag goes back up: the surface follows (grab rows with a force) and is lifted.
// Cut: the same page opens the cut recording; a right drag (the right button is the blade) from above beside the
// bunny down, then across it: springs are cut.
TEST(BrowserDevice, MouseAndSpaceGrabAndPullInPullModeARightDragCutsInCutMode) {
  ASSERT_EQ(test::shell("command -v chromium").code, 0)
      << "chromium is not installed: the browser test needs it (scripts/install_deps.sh installs it)";
  const std::string dir = test::fresh_dir("browser_button");
  fs::create_directories(dir + "/pull");
  fs::create_directories(dir + "/cut");
  // the browser starts before the recordings (its start-up is not in their realtime runs) and opens each in turn
  Browser browser;
  ASSERT_TRUE(browser.launch("about:blank", dir));
  ASSERT_TRUE(browser.attach("about:blank")) << read_file(dir + "/chromium.log");
  auto open = [&browser](const std::string& url) {
    browser.call("Page.navigate", {{"url", url}}, true);
    for (int i = 0; i < 100 && browser.eval("location.href") != url; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    return role(browser);
  };
  {
    Recording rec(dir + "/pull", "scenes/bunny_pull.json", 12.0);
    ASSERT_FALSE(rec.url.empty()) << read_file(rec.log);
    ASSERT_EQ(open(rec.url), "control");
    const auto rect = overlay_rect(browser);
    ASSERT_EQ(rect.size(), 4u);
    // in pull mode the tool passes freely until a press grabs the surface within the grab radius; first the tool to
    // the top of the view in the plane through the bunny's middle (input is relative)
    double y = 0.0;
    const auto grabbed = test::grab_bunny(browser, rect, rec, &y);
    ASSERT_TRUE(grabbed.is_object()) << "Space never grabbed the bunny" << read_file(rec.log);
    // held, then up by 0.24 of the view (about 15 mm) and held until the run ends
    std::this_thread::sleep_for(std::chrono::milliseconds(150));
    for (int step = 0; step < 60; ++step) {
      mouse(browser, rect, "mouseMoved", 0.0, y += 0.004, true);
      std::this_thread::sleep_for(std::chrono::milliseconds(16));
    }
    ASSERT_EQ(rec.wait(30), 0) << read_file(rec.log);
    space(browser, false);
    mouse(browser, rect, "mouseReleased", 0.0, y, false);
    const auto [grab_rows, grab_N] = rows_in_state(rec.out + "/haptic.csv", 2);
    EXPECT_GT(grab_rows, 300) << "the press did not grab";
    EXPECT_GT(grab_N, 0.2) << "the grabbed surface did not pull back";
    const auto summary = nlohmann::json::parse(read_file(rec.out + "/summary.json"));
    EXPECT_GT(summary["max_displacement_m"].get<double>(), 2e-3) << "the surface was not lifted";
    std::printf("[ figures ] pull: %d grab rows, largest force %.2f N, surface lifted %.1f mm; page messages %lld, "
                "longest gap %.0f ms, stalls %lld\n",
                grab_rows, grab_N, summary["max_displacement_m"].get<double>() * 1e3,
                static_cast<long long>(summary["device"]["messages"].get<int64_t>()),
                summary["device"].value("max_gap_ms", -1.0),
                static_cast<long long>(summary["device"].value("stalls", int64_t{-1})));
  }
  {
    Recording rec(dir + "/cut", "scenes/bunny_cut.json", 8.0);
    ASSERT_FALSE(rec.url.empty()) << read_file(rec.log);
    ASSERT_EQ(open(rec.url), "control");
    const auto rect = overlay_rect(browser);
    ASSERT_EQ(rect.size(), 4u);
    // the blade stands up from the tool: lowered beside the bunny, then drawn across it, once the run has started
    // (cut mode sets its whole-object lattice at rest first)
    stats_until(rec, 30.0, [](const nlohmann::json& j) { return j["servo"]["ticks"].get<int64_t>() > 0; });
    // the first right press, held still for a second: the blade goes down where the tool is and nothing sweeps
    // (the force stays within the jump limit, the tool where it was)
    const auto before = rec.stats()["browser"]["handle_m"];
    mouse(browser, rect, "mousePressed", 0.0, 0.0, true, "right");
    double still_max_N = 0.0, still_travel_m = 0.0;
    for (int i = 0; i < 50; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      const auto b = rec.stats()["browser"];
      still_max_N = std::max(still_max_N, norm(b["force_N"]));
      still_travel_m = std::max(still_travel_m, std::hypot(b["handle_m"][0].get<double>() - before[0].get<double>(),
                                                           b["handle_m"][1].get<double>() - before[1].get<double>(),
                                                           b["handle_m"][2].get<double>() - before[2].get<double>()));
    }
    mouse(browser, rect, "mouseReleased", 0.0, 0.0, false, "right");
    EXPECT_LE(still_max_N, 0.02) << "force from a right press that did not move";
    EXPECT_LT(still_travel_m, 1e-3) << "the tool swept from a right press that did not move";
    // then the tool to the left of the bunny, in the plane through its middle, and the blade across it
    ASSERT_TRUE(tool_to(browser, rect, -0.7, 0.95, 0.0)) << browser.eval("live.device.hv").dump();
    double x = -0.7, y = 0.95;
    mouse(browser, rect, "mousePressed", x, y, true, "right");
    for (int step = 0; step < 30; ++step) {
      mouse(browser, rect, "mouseMoved", x, y -= 0.032, true, "right");
      std::this_thread::sleep_for(std::chrono::milliseconds(16));
    }
    for (int step = 0; step < 70 && rec.pid > 0; ++step) {
      mouse(browser, rect, "mouseMoved", x += 0.02, y, true, "right");
      std::this_thread::sleep_for(std::chrono::milliseconds(16));
    }
    ASSERT_EQ(rec.wait(30), 0) << read_file(rec.log);
    mouse(browser, rect, "mouseReleased", x, y, false, "right");
    const auto summary = nlohmann::json::parse(read_file(rec.out + "/summary.json"));
    ASSERT_TRUE(summary.contains("cut")) << summary.dump();
    EXPECT_GT(summary["cut"]["springs_cut"].get<int64_t>(), 0) << "the blade cut nothing";
    std::printf("[ figures ] cut: %lld springs cut\n", static_cast<long long>(summary["cut"]["springs_cut"].get<int64_t>()));
  }
}

// A short recording steered through the socket (as the page does), replayed twice in lockstep: the tool path as
// recorded, and the same state hash both times.
TEST(BrowserDevice, ARecordingReplaysAlongItsPath) {
  const std::string dir = test::fresh_dir("browser_replay");
  fs::create_directories(dir);
  Recording rec(dir, "scenes/bunny_touch.json", 3.0);
  ASSERT_FALSE(rec.url.empty()) << read_file(rec.log);
  // the server is on loopback: a page of another site whose name was pointed at 127.0.0.1 (DNS rebinding) sends
  // that name as Host and Origin, which match each other, and is refused
  {
    test::WsClient rebound;
    const std::string name = "rebound.example:" + std::to_string(rec.port);
    EXPECT_EQ(rebound.open(rec.port, "/ws", "Origin: http://" + name + "\r\n", name).rfind("HTTP/1.1 403", 0), 0u);
  }
  test::WsClient page;
  ASSERT_EQ(page.open(rec.port, "/ws").rfind("HTTP/1.1 101", 0), 0u);
  EXPECT_NE(page.read().payload.find("\"role\":\"control\""), std::string::npos);
  // as the page does: the first pose is where the tool is (input is relative: it anchors there), so that the
  // pointer's coordinates are the tool's from then on
  std::vector<double> hv;
  for (int i = 0; i < 3000 && hv.empty(); ++i) {
    const auto j = nlohmann::json::parse(page.read().payload, nullptr, false);
    if (j.is_object() && j.value("t", "") == "f" && j.value("n", 0) > 0) hv = j["hv"].get<std::vector<double>>();
  }
  ASSERT_EQ(hv.size(), 3u);
  auto view = [](double v) { return std::to_string(std::clamp(v, -1.0, 1.0)); };
  ASSERT_TRUE(page.send_text("p 1 " + view(hv[0]) + " " + view(hv[1]) + " " + view(hv[2]) + " 0"));
  // down through the bunny's back and up again at about 60 messages a second, until the run ends
  int64_t seq = 1;
  for (auto end = Clock::now() + std::chrono::seconds(30); Clock::now() < end && rec.pid > 0; ++seq) {
    const double u = static_cast<double>(seq % 120) / 60.0;
    const double y = 0.95 - 1.1 * (u < 1.0 ? u : 2.0 - u);
    if (!page.send_text("p " + std::to_string(seq + 1) + " 0 " + std::to_string(y) + " 0 0")) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(16));
    int status = 0;
    if (::waitpid(rec.pid, &status, WNOHANG) == rec.pid) {
      rec.pid = -1;
      ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_file(rec.log);
    }
  }
  // the server closes the socket when the run ends; the process then writes its outputs
  if (rec.pid > 0) {
    EXPECT_EQ(rec.wait(60), 0) << read_file(rec.log);
  }
  ASSERT_EQ(rec.pid, -1) << "the 3 s recording did not end";
  const auto summary = nlohmann::json::parse(read_file(rec.out + "/summary.json"));
  EXPECT_EQ(summary["device"]["driver"], "browser");
  EXPECT_GT(summary["device"]["messages"].get<int64_t>(), 60);
  EXPECT_GT(summary["max_force_N"].get<double>(), 0.1) << "the path goes through the bunny";

  std::vector<std::string> hashes;
  for (const char* tag : {"replay_a", "replay_b"}) {
    const std::string out = dir + "/" + tag;
    const auto r = test::shell(palpate_bin() + " record " + test::source_path("scenes/bunny_touch.json") +
                               " --device replay:" + rec.out + " --mode lockstep --no-render -q --out " + out);
    ASSERT_EQ(r.code, 0) << r.out;
    hashes.push_back(hash_of(out));
    // every row the realtime run logged is in the replay, in order (the replay also has the ticks a realtime servo
    // missed, holding the row before, as the recording's servo held its pose)
    const auto replayed = tool_path(out + "/haptic.csv"), recorded = tool_path(rec.out + "/haptic.csv");
    std::size_t at = 0;
    for (const std::string& row : replayed)
      if (at < recorded.size() && row == recorded[at]) ++at;
    EXPECT_EQ(at, recorded.size()) << "recorded row " << at << " not replayed: " << recorded[std::min(at, recorded.size() - 1)];
    EXPECT_GT(recorded.size(), 2000u);
  }
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_FALSE(hashes[0].empty());
}

}  // namespace
}  // namespace palpate
