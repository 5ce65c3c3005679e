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

#include "browser/chromium.h"
#include "browser/frame_pixels.h"
#include "haptics/browser_device.h"
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

std::string palpate_bin() {
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  return std::string(bin ? bin : "build/bin") + "/palpate";
}

// A recording with the browser device, killed at the end of the test unless it ended.
struct Recording {
  Recording(const std::string& dir, const std::string& scene, double duration_s, const std::string& serve = "127.0.0.1:0") {
    log = dir + "/record.log";
    out = dir + "/rec";
    pid = test::spawn({palpate_bin(), "record", test::source_path(scene), "--device", "browser", "--serve",
                       serve, "--duration", std::to_string(duration_s), "--no-video", "--quiet", "--out", out},
                      log);
    for (auto end = Clock::now() + std::chrono::seconds(60); url.empty() && Clock::now() < end;) {
      const std::string text = read_file(log);
      const auto at = text.find("live view at http://127.0.0.1:");
      if (at != std::string::npos && text.find('\n', at) != std::string::npos)
        url = text.substr(at + 13, text.find('\n', at) - at - 13);
      else std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (!url.empty()) port = std::stoi(url.substr(url.rfind(':') + 1));
  }
  ~Recording() {
    if (pid > 0 && ::waitpid(pid, nullptr, WNOHANG) == 0) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }
  // waits for the run to end; its exit status (-1 when it did not end in time)
  int wait(int seconds) {
    for (auto end = Clock::now() + std::chrono::seconds(seconds); Clock::now() < end;) {
      int status = 0;
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        pid = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return -1;
  }
  nlohmann::json stats() const {
    return nlohmann::json::parse(test::http_get_body(port, "/stats.json"), nullptr, false);
  }
  pid_t pid = -1;
  std::string log, out, url;
  int port = 0;
};

double norm(const nlohmann::json& v) { return std::hypot(v[0].get<double>(), v[1].get<double>(), v[2].get<double>()); }

// polls /stats.json until pred(stats) holds or `seconds` pass; the last stats
template <class Pred>
nlohmann::json stats_until(const Recording& r, double seconds, Pred pred) {
  nlohmann::json s;
  for (auto end = Clock::now() + std::chrono::duration<double>(seconds); Clock::now() < end;) {
    s = r.stats();
    if (s.is_object() && s.contains("browser") && pred(s)) return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return s;
}

// the page's role once it has one ("control" or "watch"), waiting at most 30 s
std::string role(Browser& b) {
  for (int i = 0; i < 300; ++i) {
    const auto v = b.eval("live.device ? live.device.role : 'none'");
    if (v.is_string() && v.get<std::string>() != "none") return v.get<std::string>();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return "none";
}

// the overlay's client rectangle: left, top, width, height
std::vector<double> overlay_rect(Browser& b) {
  const auto v = b.eval(
      "(() => { const r = document.getElementById('overlay').getBoundingClientRect();"
      " return [r.left, r.top, r.width, r.height]; })()");
  return v.is_array() ? v.get<std::vector<double>>() : std::vector<double>{};
}

// a mouse event at view coordinates (x, y in -1..1), `button` ("left" or "right") held when `held`
void mouse(Browser& b, const std::vector<double>& rect, const std::string& type, double x, double y, bool held,
           const std::string& button = "left") {
  b.call("Input.dispatchMouseEvent",
         {{"type", type},
          {"x", rect[0] + (x + 1) / 2 * rect[2]},
          {"y", rect[1] + (1 - y) / 2 * rect[3]},
          {"button", button},
          {"buttons", held ? (button == "right" ? 2 : 1) : 0},
          {"clickCount", type == "mouseMoved" ? 0 : 1}},
         true);
}

// the tool's view coordinates (x, y, depth in -1..1) as the page last heard them, and the view's half sizes in mm
std::vector<double> tool_view(Browser& b) {
  const auto v = b.eval("live.device.hv");
  return v.is_array() && v.size() == 3 ? v.get<std::vector<double>>() : std::vector<double>{};
}

// Moves the tool to view coordinates (x, y, depth) as a person does with relative input: the wheel for the depth
// (1 mm a notch, the page's default), then left drags of at most 0.5 of the view from the overlay's centre, button
// up between them. Waits until the page hears the tool there (within 0.03 of the view), at most 10 s.
bool tool_to(Browser& b, const std::vector<double>& rect, double x, double y, double depth) {
  // the page knows where the tool is once the servo runs
  for (int i = 0; i < 300 && b.eval("live.device.ticks").get<int64_t>() == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  for (int round = 0; round < 3; ++round) {
    const auto hv = tool_view(b);
    const auto mm = b.eval("live.device.mm");
    if (hv.empty() || !mm.is_array() || mm[2].get<double>() <= 0.0) return false;
    const double notches = (depth - hv[2]) * mm[2].get<double>();
    if (std::abs(notches) >= 0.5)
      b.call("Input.dispatchMouseEvent", {{"type", "mouseWheel"}, {"x", rect[0] + rect[2] / 2}, {"y", rect[1] + rect[3] / 2},
                                          {"deltaX", 0}, {"deltaY", std::round(notches) * 100.0}}, true);
    const double dx = x - hv[0], dy = y - hv[1];
    const int strokes = static_cast<int>(std::ceil(std::max(std::abs(dx), std::abs(dy)) / 0.5));
    for (int k = 0; k < strokes; ++k) {
      mouse(b, rect, "mousePressed", 0.0, 0.0, true);
      for (int i = 1; i <= 10; ++i) {
        mouse(b, rect, "mouseMoved", dx / strokes * i / 10, dy / strokes * i / 10, true);
        std::this_thread::sleep_for(std::chrono::milliseconds(16));
      }
      mouse(b, rect, "mouseReleased", dx / strokes, dy / strokes, false);
    }
    for (int i = 0; i < 100; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      const auto now = tool_view(b);
      if (!now.empty() && std::abs(now[0] - x) < 0.03 && std::abs(now[1] - y) < 0.03 && std::abs(now[2] - depth) < 0.03)
        return true;
      if (i > 10 && !now.empty() && (now[0] - hv[0]) * (now[0] - hv[0]) + (now[1] - hv[1]) * (now[1] - hv[1]) > 0.0 &&
          i % 10 == 0)
        break;  // moved, not there yet (the hand lags, or a drag was clamped at the view's edge): another round
    }
  }
  const auto now = tool_view(b);
  return !now.empty() && std::abs(now[0] - x) < 0.03 && std::abs(now[1] - y) < 0.03 && std::abs(now[2] - depth) < 0.03;
}

// the Space key going down or up (the page's button)
void space(Browser& b, bool down) {
  b.call("Input.dispatchKeyEvent",
         {{"type", down ? "keyDown" : "keyUp"}, {"code", "Space"}, {"key", " "}, {"windowsVirtualKeyCode", 32}}, true);
}

// Presses the tool onto the bunny's back from where it is (a left drag down from the top of the view, in the plane
// through the bunny's middle), a step every 40 ms, until the force passes until_N; the button stays down. The force
// reached.
double press_onto_bunny(Browser& b, const std::vector<double>& rect, const Recording& rec, double until_N = 0.3) {
  if (!tool_to(b, rect, 0.0, 0.95, 0.0)) return 0.0;
  mouse(b, rect, "mousePressed", 0.0, 0.95, true);
  double f = 0.0;
  for (double y = 0.95; y > -0.6 && f <= until_N; y -= 0.01) {
    mouse(b, rect, "mouseMoved", 0.0, y, true);
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    const auto s = rec.stats();
    if (s.is_object() && s.contains("browser")) f = norm(s["browser"]["force_N"]);
  }
  return f;
}

TEST(BrowserDevice, PageSteersTheToolOntoTheBunnyASecondPageWatchesClosingFadesTheForce) {
  ASSERT_EQ(test::shell("command -v chromium").code, 0)
      << "chromium is not installed: the browser test needs it (scripts/install_deps.sh installs it)";
  const std::string dir = test::fresh_dir("browser_device");
  fs::create_directories(dir);
  Recording rec(dir, "scenes/bunny_touch.json", 120.0);
  ASSERT_FALSE(rec.url.empty()) << read_file(rec.log);

  Browser browser;
  ASSERT_TRUE(browser.launch(rec.url, dir));
  ASSERT_TRUE(browser.attach(rec.url)) << read_file(dir + "/chromium.log");
  const std::string first_target = browser.target();
  ASSERT_EQ(role(browser), "control");
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

// What the device did over `seconds` with no input: the largest force from `settle_s` on (the press before fades out
// over the watchdog), and how far the handle went from where it was at settle_s.
struct Quiet {
  double max_N = 0.0;
  double travel_m = 0.0;
  bool engaged = false;
};
Quiet quiet_for(const Recording& rec, double seconds, double settle_s = 0.5) {
  Quiet q;
  std::vector<double> at;
  const auto t0 = Clock::now();
  for (auto end = t0 + std::chrono::duration<double>(seconds); Clock::now() < end;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const auto s = rec.stats();
    if (!s.is_object() || !s.contains("browser")) continue;
    if (std::chrono::duration<double>(Clock::now() - t0).count() < settle_s) continue;
    const auto& b = s["browser"];
    const std::vector<double> h = b["handle_m"].get<std::vector<double>>();
    if (at.empty()) at = h;
    q.max_N = std::max(q.max_N, norm(b["force_N"]));
    q.travel_m = std::max(q.travel_m, std::hypot(h[0] - at[0], h[1] - at[1], h[2] - at[2]));
    q.engaged = q.engaged || b["engaged"].get<bool>();
  }
  return q;
}

// Force before intent, tried as people do it, mid-press on the bunny: the steering tab goes to the background (it
// lets go and never pulses), the page is reloaded (the new page pushes nothing until its user moves, then the press
// comes back), and the steering tab is closed with a watching tab open (the watcher takes control and pushes
// nothing).
TEST(BrowserDevice, AHiddenTabAReloadOrAWatcherTakingOverPushesNothingUntilTheHandMoves) {
  ASSERT_EQ(test::shell("command -v chromium").code, 0)
      << "chromium is not installed: the browser test needs it (scripts/install_deps.sh installs it)";
  const std::string dir = test::fresh_dir("browser_intent");
  fs::create_directories(dir);
  Recording rec(dir, "scenes/bunny_touch.json", 120.0);
  ASSERT_FALSE(rec.url.empty()) << read_file(rec.log);
  Browser browser;
  ASSERT_TRUE(browser.launch(rec.url, dir));
  ASSERT_TRUE(browser.attach(rec.url)) << read_file(dir + "/chromium.log");
  ASSERT_EQ(role(browser), "control");
  const auto rect = overlay_rect(browser);
  ASSERT_EQ(rect.size(), 4u);
  ASSERT_GT(press_onto_bunny(browser, rect, rec), 0.3);

  // the tab goes to the background mid-press: it lets go; nothing comes back for 3 s
  browser.eval("Object.defineProperty(document, 'visibilityState', {configurable: true, get: () => 'hidden'});"
               "document.dispatchEvent(new Event('visibilitychange')); true");
  const Quiet hidden = quiet_for(rec, 3.5);
  EXPECT_EQ(hidden.max_N, 0.0) << "a hidden tab's force came back";
  EXPECT_LT(hidden.travel_m, 1e-4);
  browser.eval("Object.defineProperty(document, 'visibilityState', {configurable: true, get: () => 'visible'});"
               "document.dispatchEvent(new Event('visibilitychange')); true");
  mouse(browser, rect, "mouseReleased", 0.0, 0.0, false);
  // a little drag down: the press comes back
  auto repress = [&browser, &rect, &rec] {
    mouse(browser, rect, "mousePressed", 0.0, 0.0, true);
    for (int i = 1; i <= 10; ++i) {
      mouse(browser, rect, "mouseMoved", 0.0, -0.002 * i, true);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return norm(stats_until(rec, 3.0, [](const nlohmann::json& j) { return norm(j["browser"]["force_N"]) > 0.2; })
                    ["browser"]["force_N"]);
  };
  EXPECT_GT(repress(), 0.2) << "the press did not come back after the tab came back and the hand moved";

  // reloaded mid-press: the new page steers, and pushes nothing until its user moves
  browser.call("Page.reload", nlohmann::json::object(), true);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ASSERT_EQ(role(browser), "control");
  const Quiet reloaded = quiet_for(rec, 2.0);
  EXPECT_EQ(reloaded.max_N, 0.0) << "the reloaded page pushed before any input";
  EXPECT_LT(reloaded.travel_m, 1e-4) << "the tool moved after the reload, before any input";
  EXPECT_FALSE(reloaded.engaged);
  mouse(browser, rect, "mouseReleased", 0.0, 0.0, false);
  EXPECT_GT(repress(), 0.2) << "the press did not come back once the reloaded page's user moved";

  // a second tab watches; the steering one closes mid-press: the watcher takes control and pushes nothing
  const std::string first = browser.target();
  ASSERT_TRUE(browser.open_page(rec.url));
  ASSERT_EQ(role(browser), "watch");
  browser.call("Target.closeTarget", {{"targetId", first}}, false);
  for (int i = 0; i < 100 && browser.eval("live.device.role") != "control"; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_EQ(browser.eval("live.device.role"), "control") << "the watcher was not offered control";
  const Quiet taken = quiet_for(rec, 2.0);
  EXPECT_EQ(taken.max_N, 0.0) << "the watcher that took over pushed before any input";
  EXPECT_LT(taken.travel_m, 1e-4);
  EXPECT_EQ(browser.eval("live.device.sent"), 0) << "the watcher sent poses before any input";
  std::printf("[ figures ] after the tab hid, the reload, the takeover: largest force %.3f / %.3f / %.3f N, tool moved "
              "%.2f / %.2f / %.2f mm\n", hidden.max_N, reloaded.max_N, taken.max_N, hidden.travel_m * 1e3,
              reloaded.travel_m * 1e3, taken.travel_m * 1e3);
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
    ASSERT_TRUE(tool_to(browser, rect, 0.0, 0.7, 0.0)) << browser.eval("live.device.hv").dump();
    double y = 0.7;
    mouse(browser, rect, "mousePressed", 0.0, y, true);
    bool grabbed = false, key_down = false;
    nlohmann::json last;
    for (int step = 0; y > -0.6 && !grabbed; ++step, y -= 0.01) {
      mouse(browser, rect, "mouseMoved", 0.0, y, true);
      if ((step % 4 < 2) != key_down) space(browser, key_down = !key_down);
      std::this_thread::sleep_for(std::chrono::milliseconds(16));
      const auto st = rec.stats();
      if (st.is_object() && st.contains("browser")) last = st["browser"];
      grabbed = key_down && last.is_object() && norm(last["force_N"]) > 0.05;
    }
    ASSERT_TRUE(grabbed) << "Space never grabbed the bunny; last: " << last.dump() << read_file(rec.log);
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

// The next message of type `t` on a page's socket (feedback skipped), or null after `ms`.
nlohmann::json next_of(test::WsClient& c, const std::string& t, int ms = 3000) {
  for (auto end = Clock::now() + std::chrono::milliseconds(ms); Clock::now() < end;) {
    const auto r = c.read(ms);
    if (r.opcode < 0) break;
    const auto j = nlohmann::json::parse(r.payload, nullptr, false);
    if (j.is_object() && j.value("t", "") == t) return j;
  }
  return nullptr;
}

// --serve 0.0.0.0: the address printed carries a random token; a page without it (or with another) watches and
// cannot steer, one with it steers. On every bind a Host that is not this machine's name is refused (DNS rebinding),
// on the page too, and an Origin is compared whole (127.0.0.1:P.evil.example is another site).
TEST(BrowserDevice, RemoteUseNeedsTheTokenForeignNamesAndOriginsAreRefused) {
  const std::string dir = test::fresh_dir("browser_token");
  fs::create_directories(dir);
  Recording rec(dir, "scenes/bunny_touch.json", 20.0, "0.0.0.0:0");
  ASSERT_FALSE(rec.url.empty()) << read_file(rec.log);
  const auto at = rec.url.find("?token=");
  ASSERT_NE(at, std::string::npos) << rec.url;
  const std::string token = rec.url.substr(at + 7, rec.url.find('/', at) - at - 7);
  ASSERT_EQ(token.size(), 32u) << rec.url;
  EXPECT_EQ(token.find_first_not_of("0123456789abcdef"), std::string::npos);
  const std::string port = std::to_string(rec.port);

  // names of other sites pointed at this machine: refused, page and socket alike; an address literal is fine
  EXPECT_EQ(test::http_get(rec.port, "/", "evil.test:" + port).rfind("HTTP/1.1 403", 0), 0u);
  EXPECT_EQ(test::http_get(rec.port, "/stats.json", "rebound.example").rfind("HTTP/1.1 403", 0), 0u);
  EXPECT_EQ(test::http_get(rec.port, "/", "10.1.2.3:" + port).rfind("HTTP/1.1 200", 0), 0u);
  {
    test::WsClient foreign;
    EXPECT_EQ(foreign.open(rec.port, "/ws?token=" + token, "Origin: http://evil.test:" + port + "\r\n", "evil.test:" + port)
                  .rfind("HTTP/1.1 403", 0), 0u);
  }
  {
    test::WsClient prefixed;  // the server's own origin as a prefix of another site's
    EXPECT_EQ(prefixed.open(rec.port, "/ws?token=" + token, "Origin: http://127.0.0.1:" + port + ".evil.example\r\n")
                  .rfind("HTTP/1.1 403", 0), 0u);
  }
  // without the token, or with another: watching only, whatever it sends
  test::WsClient bare, wrong;
  ASSERT_EQ(bare.open(rec.port, "/ws").rfind("HTTP/1.1 101", 0), 0u);
  const auto bare_hello = next_of(bare, "hello");
  ASSERT_TRUE(bare_hello.is_object());
  EXPECT_EQ(bare_hello["role"], "watch");
  EXPECT_FALSE(bare_hello["steer"].get<bool>());
  std::string other = token;
  other[0] = other[0] == 'a' ? 'b' : 'a';
  ASSERT_EQ(wrong.open(rec.port, "/ws?token=" + other).rfind("HTTP/1.1 101", 0), 0u);
  EXPECT_FALSE(next_of(wrong, "hello")["steer"].get<bool>());
  for (int i = 1; i <= 30; ++i) {
    ASSERT_TRUE(bare.send_text("p " + std::to_string(i) + " " + std::to_string(0.01 * i) + " 0 0 1"));
    ASSERT_TRUE(wrong.send_text("p " + std::to_string(i) + " " + std::to_string(-0.01 * i) + " 0 0 1"));
    std::this_thread::sleep_for(std::chrono::milliseconds(15));
  }
  auto s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["ignored"] >= 60; });
  EXPECT_EQ(s["browser"]["ignored"], 60) << s["browser"].dump();
  EXPECT_EQ(s["browser"]["messages"], 0);
  EXPECT_FALSE(s["browser"]["controlled"].get<bool>());
  EXPECT_TRUE(s["browser"]["token_required"].get<bool>());
  // with the token: control, and its poses reach the device
  test::WsClient page;
  ASSERT_EQ(page.open(rec.port, "/ws?token=" + token).rfind("HTTP/1.1 101", 0), 0u);
  const auto hello = next_of(page, "hello");
  EXPECT_EQ(hello["role"], "control") << hello.dump();
  for (int i = 1; i <= 30; ++i) {
    ASSERT_TRUE(page.send_text("p " + std::to_string(i) + " " + std::to_string(0.002 * i) + " 0.5 -0.5 0"));
    std::this_thread::sleep_for(std::chrono::milliseconds(15));
  }
  s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["messages"] >= 30; });
  EXPECT_EQ(s["browser"]["messages"], 30) << s["browser"].dump();
  EXPECT_TRUE(s["browser"]["engaged"].get<bool>()) << s["browser"].dump();
}

// Control follows the hand: a controller that stops steering (however often it says it is alive, or repeats an old
// pose) yields to a page that steers once the watchdog has passed, and not before; when every socket slot is taken a
// new page gets the slot of the one longest without steering, never the steering one's.
TEST(BrowserDevice, ControlFollowsTheHandAndIdleSocketsGiveUpTheirSlots) {
  const std::string dir = test::fresh_dir("browser_takeover");
  fs::create_directories(dir);
  Recording rec(dir, "scenes/bunny_touch.json", 30.0);
  ASSERT_FALSE(rec.url.empty()) << read_file(rec.log);
  test::WsClient a, b;
  ASSERT_EQ(a.open(rec.port, "/ws").rfind("HTTP/1.1 101", 0), 0u);
  ASSERT_EQ(next_of(a, "hello")["role"], "control");
  ASSERT_EQ(b.open(rec.port, "/ws").rfind("HTTP/1.1 101", 0), 0u);
  ASSERT_EQ(next_of(b, "hello")["role"], "watch");
  // a steers; b's poses meanwhile are ignored
  int64_t seq_a = 0, seq_b = 0;
  for (int i = 0; i < 40; ++i) {
    ASSERT_TRUE(a.send_text("p " + std::to_string(++seq_a) + " " + std::to_string(0.001 * i) + " 0.5 -0.5 0"));
    ASSERT_TRUE(b.send_text("p " + std::to_string(++seq_b) + " 0.3 0.3 0 0"));
    std::this_thread::sleep_for(std::chrono::milliseconds(15));
  }
  auto s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["ignored"] >= 40; });
  EXPECT_EQ(s["browser"]["ignored"], 40) << s["browser"].dump();
  EXPECT_EQ(s["browser"]["takeovers"], 0);
  // a stops steering but keeps its socket busy: "k" and its last pose again, every 20 ms for a second
  for (int i = 0; i < 50; ++i) {
    ASSERT_TRUE(a.send_text(i % 2 ? "k" : "p " + std::to_string(seq_a) + " 0.039 0.5 -0.5 0"));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  // b steers: it takes control (a is told it watches), and its first pose moves nothing
  ASSERT_TRUE(b.send_text("p " + std::to_string(++seq_b) + " 0.3 0.3 0 0"));
  EXPECT_EQ(next_of(b, "hello")["role"], "control");
  EXPECT_EQ(next_of(a, "hello")["role"], "watch");
  s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["takeovers"] >= 1; });
  EXPECT_EQ(s["browser"]["takeovers"], 1) << s["browser"].dump();
  EXPECT_FALSE(s["browser"]["engaged"].get<bool>()) << "a page that took over is engaged before it moved";
  EXPECT_EQ(norm(s["browser"]["force_N"]), 0.0);
  // every slot taken (a, b, c, d), b steering: a fifth page gets a's slot (longest without steering)
  test::WsClient c, d, e;
  ASSERT_EQ(c.open(rec.port, "/ws").rfind("HTTP/1.1 101", 0), 0u);
  ASSERT_EQ(d.open(rec.port, "/ws").rfind("HTTP/1.1 101", 0), 0u);
  ASSERT_TRUE(b.send_text("p " + std::to_string(++seq_b) + " 0.31 0.3 0 0"));
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_EQ(e.open(rec.port, "/ws").rfind("HTTP/1.1 101", 0), 0u) << "a fifth page was refused while an idle one held a slot";
  EXPECT_EQ(a.read_until(8).opcode, 8) << "the idle page's socket was not the one closed";
  s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["evicted"] >= 1; });
  EXPECT_EQ(s["browser"]["evicted"], 1);
  EXPECT_EQ(s["browser"]["pages"], 4);
  ASSERT_TRUE(b.send_text("p " + std::to_string(++seq_b) + " 0.32 0.3 0 0"));
  s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["engaged"].get<bool>(); });
  EXPECT_TRUE(s["browser"]["engaged"].get<bool>()) << "b still steers: " << s["browser"].dump();
}

}  // namespace
}  // namespace palpate
