#pragma once
/// BrowserControl: the live view's side of the browser device. Keeps the pages connected over /ws in order: the
/// first controls (its pointer messages go to the BrowserLink), the others watch; when the controller leaves or is
/// closed for garbage the link is released (the device fades its force out) and the oldest watcher takes over.
/// Sends every page the device force about 60 times a second and gathers the latency figures for /stats.json.
/// Thread: the HttpServer's loop only (its callbacks, tick and handler).

#include <cstdint>
#include <deque>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "haptics/browser_link.h"
#include "tools/live/http_server.h"

namespace palpate {

/// The /ws side of a live view. Not copyable.
class BrowserControl {
 public:
  /// http and link must outlive it; installs its WebSocket callbacks on http (before http.start()).
  BrowserControl(HttpServer* http, BrowserLink* link);
  BrowserControl(const BrowserControl&) = delete;
  BrowserControl& operator=(const BrowserControl&) = delete;

  /// Sends each page the newest feedback (with the live view's newest frame index). Thread: loop.
  void tick(int64_t frame);
  /// The "browser" block of /stats.json: role counts, messages, the force and the latency percentiles. Thread: loop.
  nlohmann::json stats();

 private:
  void open(int64_t id);
  void message(int64_t id, std::string_view text);
  void close(int64_t id, const std::string& why);
  std::string hello(int64_t id) const;

  HttpServer* http_;
  BrowserLink* link_;
  std::vector<int64_t> pages_;     // open sockets, oldest first; the first controls
  int64_t last_seq_ = 0;           // the controller's newest pose
  int64_t fed_seq_ = -1;           // the newest seq whose input-to-force figure was taken
  int64_t messages_ = 0, ignored_ = 0, refused_ = 0, controllers_ = 0;
  std::string last_refusal_;
  // the last kWindow figures of each latency (server: receipt to force, us; page: event to force / to frame, ms)
  static constexpr std::size_t kWindow = 600;
  std::deque<double> server_us_, page_force_ms_, page_frame_ms_;
};

}  // namespace palpate
