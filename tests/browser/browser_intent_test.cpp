// The browser device's safety, end to end against `palpate record --device browser --serve` as a second process: no
// force before the hand moves (a tab hidden, a page reloaded, a watcher taking over mid-press, in headless Chromium),
// control that follows the steering hand, idle sockets that give up their slots, and remote use that needs the
// printed token while foreign names and origins are refused (over the page's protocol).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "browser/browser_page.h"
#include "browser/chromium.h"
#include "support/cli_run.h"
#include "support/fixtures.h"
#include "support/http_get.h"
#include "support/json_file.h"
#include "support/read_file.h"
#include "support/ws_client.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;
using test::Browser;
using test::Clock;
using test::next_of;
using test::norm;
using test::overlay_rect;
using test::press_onto_bunny;
using test::Quiet;
using test::quiet_for;
using test::read_file;
using test::Recording;
using test::role;
using test::mouse;
using test::stats_until;

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
  Browser browser;
  ASSERT_EQ(test::steer_page(browser, rec, dir), "");
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

// The scene owns the browser device's timing: device.browser_send_ms reaches the page in its hello (it sends its
// pointer that often), and device.browser_stall_ms is the device's watchdog: with 800 ms, a page silent for half a
// second still has its force (the default 250 ms would have faded it), and the force fades once the 800 ms pass.
TEST(BrowserDevice, TheScenesWatchdogAndSendIntervalReachTheDeviceAndThePage) {
  const std::string dir = test::fresh_dir("browser_timing");
  fs::create_directories(dir);
  nlohmann::json scene = nlohmann::json::parse(read_file(test::source_path("scenes/bunny_touch.json")));
  scene["mesh"]["file"] = test::source_path("scenes/bunny.obj");
  scene["device"]["browser_stall_ms"] = 800;
  scene["device"]["browser_send_ms"] = 30;
  const std::string path = dir + "/timing.json";
  test::write_text(path, scene.dump());
  Recording rec(dir, path, 30.0);
  ASSERT_FALSE(rec.url.empty()) << read_file(rec.log);
  test::WsClient page;
  ASSERT_EQ(page.open(rec.port, "/ws").rfind("HTTP/1.1 101", 0), 0u);
  const auto hello = next_of(page, "hello");
  EXPECT_EQ(hello["send_ms"], 30.0) << hello.dump();
  for (int i = 1; i <= 20; ++i) {
    ASSERT_TRUE(page.send_text("p " + std::to_string(i) + " " + std::to_string(0.002 * i) + " 0.5 -0.5 0"));
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
  }
  auto s = stats_until(rec, 5.0, [](const nlohmann::json& j) { return j["browser"]["force_scale"] >= 0.999; });
  ASSERT_GE(s["browser"]["force_scale"].get<double>(), 0.999) << s["browser"].dump();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  s = rec.stats();
  EXPECT_GE(s["browser"]["force_scale"].get<double>(), 0.999) << "faded after 0.5 s of silence: " << s["browser"].dump();
  s = stats_until(rec, 3.0, [](const nlohmann::json& j) { return j["browser"]["force_scale"] <= 0.0; });
  EXPECT_EQ(s["browser"]["force_scale"].get<double>(), 0.0) << s["browser"].dump();
  // the live page itself takes the interval from its hello (its own default is 15 ms)
  Browser browser;
  ASSERT_TRUE(browser.launch("about:blank", dir));
  ASSERT_TRUE(browser.attach("about:blank")) << read_file(dir + "/chromium.log");
  browser.call("Page.navigate", {{"url", rec.url}}, true);
  ASSERT_NE(test::role(browser), "none");
  EXPECT_EQ(browser.eval("live.device.sendMs"), 30);
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
