#pragma once
// What the browser tests share: a `palpate record --device browser --serve` run as a second process, its /stats.json,
// and a headless Chromium page driven as a person does (mouse, wheel and keys through DevTools Input; the tool moved
// by relative drags, as the page's input is).
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "browser/chromium.h"
#include "support/fixtures.h"
#include "support/http_get.h"
#include "support/read_file.h"
#include "support/ws_client.h"

namespace palpate::test {

inline std::string palpate_bin() {
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  return std::string(bin ? bin : "build/bin") + "/palpate";
}

// A recording with the browser device, killed at the end of the test unless it ended.
struct Recording {
  // scene: a path from the source folder, or an absolute one
  Recording(const std::string& dir, const std::string& scene, double duration_s, const std::string& serve = "127.0.0.1:0") {
    log = dir + "/record.log";
    out = dir + "/rec";
    pid = spawn({palpate_bin(), "record", scene.rfind('/', 0) == 0 ? scene : source_path(scene), "--device", "browser", "--serve",
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
    return nlohmann::json::parse(http_get_body(port, "/stats.json"), nullptr, false);
  }
  pid_t pid = -1;
  std::string log, out, url;
  int port = 0;
};

// haptic.csv's rows as numbers (the header left out)
inline std::vector<std::vector<double>> log_rows(const std::string& path) {
  std::vector<std::vector<double>> rows;
  std::istringstream in(read_file(path));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<double> r;
    std::istringstream l(line);
    for (std::string c; std::getline(l, c, ',');) r.push_back(std::stod(c));
    rows.push_back(r);
  }
  return rows;
}

inline double norm(const nlohmann::json& v) { return std::hypot(v[0].get<double>(), v[1].get<double>(), v[2].get<double>()); }

// polls /stats.json until pred(stats) holds or `seconds` pass; the last stats
template <class Pred>
inline nlohmann::json stats_until(const Recording& r, double seconds, Pred pred) {
  nlohmann::json s;
  for (auto end = Clock::now() + std::chrono::duration<double>(seconds); Clock::now() < end;) {
    s = r.stats();
    if (s.is_object() && s.contains("browser") && pred(s)) return s;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return s;
}

// the page's role once it has one ("control" or "watch"), waiting at most 30 s
inline std::string role(Browser& b) {
  for (int i = 0; i < 300; ++i) {
    const auto v = b.eval("live.device ? live.device.role : 'none'");
    if (v.is_string() && v.get<std::string>() != "none") return v.get<std::string>();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return "none";
}

// the overlay's client rectangle: left, top, width, height
inline std::vector<double> overlay_rect(Browser& b) {
  const auto v = b.eval(
      "(() => { const r = document.getElementById('overlay').getBoundingClientRect();"
      " return [r.left, r.top, r.width, r.height]; })()");
  return v.is_array() ? v.get<std::vector<double>>() : std::vector<double>{};
}

// a mouse event at view coordinates (x, y in -1..1), `button` ("left" or "right") held when `held`
inline void mouse(Browser& b, const std::vector<double>& rect, const std::string& type, double x, double y, bool held,
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
inline std::vector<double> tool_view(Browser& b) {
  const auto v = b.eval("live.device.hv");
  return v.is_array() && v.size() == 3 ? v.get<std::vector<double>>() : std::vector<double>{};
}

// Moves the tool to view coordinates (x, y, depth) as a person does with relative input: the wheel for the depth
// (1 mm a notch, the page's default), then left drags of at most 0.5 of the view from the overlay's centre, button
// up between them. Waits until the page hears the tool there (within 0.03 of the view), at most 10 s.
inline bool tool_to(Browser& b, const std::vector<double>& rect, double x, double y, double depth) {
  // the page knows where the tool is once the servo runs
  for (int i = 0; i < 300 && b.eval("live.device.ticks").get<int64_t>() == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  for (int round = 0; round < 5; ++round) {
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
inline void space(Browser& b, bool down) {
  b.call("Input.dispatchKeyEvent",
         {{"type", down ? "keyDown" : "keyUp"}, {"code", "Space"}, {"key", " "}, {"windowsVirtualKeyCode", 32}}, true);
}

// Presses the tool onto the bunny's back from where it is (a left drag down from the top of the view, in the plane
// through the bunny's middle), a step every 40 ms, until the force passes until_N; the button stays down. The force
// reached.
inline double press_onto_bunny(Browser& b, const std::vector<double>& rect, const Recording& rec, double until_N = 0.3) {
  // (a loaded machine can leave the tool a little short of the view's top: a start above the bunny serves as well)
  if (!tool_to(b, rect, 0.0, 0.95, 0.0)) {
    const auto at = tool_view(b);
    if (at.empty() || std::abs(at[0]) > 0.05 || at[1] < 0.85 || std::abs(at[2]) > 0.05) return 0.0;
  }
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
// Grabs the bunny's back in pull mode as a person does: the tool to the top of the view in the plane through the
// bunny's middle, a left drag down with Space pressed and let go on the way, until a press with Space down holds the
// surface (a force above 0.05 N). The button and Space stay down; *y_out: where the drag is. The last browser stats
// (empty when it never grabbed).
inline nlohmann::json grab_bunny(Browser& b, const std::vector<double>& rect, const Recording& rec, double* y_out) {
  // a loaded machine can leave the tool behind the drag so that the sweep passes the back before a press with Space
  // down lands on it: then the drag is let go and tried again from the top, each time at half the speed
  for (int attempt = 0; attempt < 3; ++attempt) {
    if (!tool_to(b, rect, 0.0, 0.7, 0.0)) return nullptr;
    const double step_y = 0.01 / (1 << attempt);
    double y = 0.7;
    mouse(b, rect, "mousePressed", 0.0, y, true);
    bool key_down = false;
    nlohmann::json last;
    for (int step = 0; y > -0.6; ++step, y -= step_y) {
      mouse(b, rect, "mouseMoved", 0.0, y, true);
      if ((step % 4 < 2) != key_down) space(b, key_down = !key_down);
      std::this_thread::sleep_for(std::chrono::milliseconds(16));
      const auto st = rec.stats();
      if (st.is_object() && st.contains("browser")) last = st["browser"];
      if (key_down && last.is_object() && norm(last["force_N"]) > 0.05) {
        *y_out = y;
        return last;
      }
    }
    if (key_down) space(b, false);
    mouse(b, rect, "mouseReleased", 0.0, y, false);
  }
  return nullptr;
}

// What the device did over `seconds` with no input: the largest force from `settle_s` on (the press before fades out
// over the watchdog), and how far the handle went from where it was at settle_s.
struct Quiet {
  double max_N = 0.0;
  double travel_m = 0.0;
  bool engaged = false;
};
inline Quiet quiet_for(const Recording& rec, double seconds, double settle_s = 0.5) {
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


// The next message of type `t` on a page's socket (feedback skipped), or null after `ms`.
inline nlohmann::json next_of(WsClient& c, const std::string& t, int ms = 3000) {
  for (auto end = Clock::now() + std::chrono::milliseconds(ms); Clock::now() < end;) {
    const auto r = c.read(ms);
    if (r.opcode < 0) break;
    const auto j = nlohmann::json::parse(r.payload, nullptr, false);
    if (j.is_object() && j.value("t", "") == t) return j;
  }
  return nullptr;
}


// Headless Chromium opened on a recording's page, which steers: "" or what went wrong.
inline std::string steer_page(Browser& b, const Recording& rec, const std::string& dir) {
  if (rec.url.empty()) return "the recording printed no address: " + read_file(rec.log);
  if (!b.launch(rec.url, dir)) return "chromium did not start";
  if (!b.attach(rec.url)) return "no page at " + rec.url + ": " + read_file(dir + "/chromium.log");
  const std::string r = role(b);
  return r == "control" ? "" : "the page's role is '" + r + "', not control";
}

}  // namespace palpate::test
