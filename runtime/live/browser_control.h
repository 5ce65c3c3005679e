#pragma once
/// BrowserControl: the live view's side of the browser device. Keeps the pages connected over /ws; one of them at a
/// time steers (its pose messages go to the BrowserLink), the others watch. Control follows the hand: only a pose
/// message with a new number is activity; a page that steers while the controller has been silent past the
/// watchdog takes control, without a step (the device anchors each page's control where the tool is). When the
/// controller leaves or is closed for garbage the link is released (the device fades its force out) and the oldest
/// page that may steer is offered control. The steering page's controls (mode, stiffness, tool radius, reset) are
/// checked against the scene's bounds (core/scene_controls.h) and handed to the device with a new seq; a refused one
/// is answered with why, the socket kept. A page may steer only with the server's token when it has one (a bind
/// that is not loopback); without it, it watches. When every socket slot is taken, the page that has gone longest
/// without steering gives its slot to a new one. Sends every page the device force about 60 times a second and
/// gathers the latency figures for /stats.json. Thread: the HttpServer's loop only (its callbacks, tick and handler).

#include <cstdint>
#include <deque>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/controls.h"
#include "core/scene.h"
#include "haptics/devices/browser_device.h"
#include "haptics/devices/browser_link.h"
#include "runtime/live/http_server.h"

namespace palpate {

struct BrowserMessage;

/// How the pages get control. Plain data.
struct BrowserControlParams {
  std::string token;              ///< non-empty: a page steers only when its /ws request carries ?token=THIS
  /// a controller silent this long (the device's watchdog: its stall and fade) yields to a page that steers
  double stale_ms = 1e3 * BrowserParams{}.watchdog_s();
  double send_ms = scene_defaults().device.browser_send_ms;  ///< the pointer's send interval the page is told
  const Scene* scene = nullptr;   ///< the run's scene: the steering page's controls (mode, stiffness, tool radius,
                                  ///< reset) are checked against it (core/scene_controls.h); null: no controls
};

/// The /ws side of a live view. Not copyable.
class BrowserControl {
 public:
  /// http and link must outlive it; installs its WebSocket callbacks on http (before http.start()).
  BrowserControl(HttpServer* http, BrowserLink* link, BrowserControlParams params = {});
  BrowserControl(const BrowserControl&) = delete;
  BrowserControl& operator=(const BrowserControl&) = delete;

  /// Sends each page the newest feedback (with the live view's newest frame index). Thread: loop.
  void tick(int64_t frame);
  /// The "browser" block of /stats.json: role counts, messages, the force and the latency percentiles. Thread: loop.
  nlohmann::json stats();
  /// Says to every page that the run ended and where its outputs are (the page clears its force). Thread: loop.
  void run_ended(const std::string& out_dir);

 private:
  struct Page {
    int64_t id = 0;
    bool may_steer = true;        // token given (or none needed)
    int64_t opened_ns = 0;
    int64_t last_pose_ns = 0;     // its newest pose message (0: none)
    int64_t last_seq = 0;         // its newest pose number
  };
  void open(int64_t id, const HttpRequest& request);
  void message(int64_t id, std::string_view text);
  void close(int64_t id, const std::string& why);
  int64_t evict();
  Page* find(int64_t id);
  void give_control(Page* page, int64_t now_ns);
  bool controller_stale(int64_t now_ns) const;
  std::string hello(const Page& page) const;
  // the steering page's controls or reset: checked against the scene, then handed to the device and said to every page
  void apply_control(Page* page, const BrowserMessage& m, int64_t now_ns);
  std::string controls_message() const;

  HttpServer* http_;
  BrowserLink* link_;
  BrowserControlParams params_;
  std::vector<Page> pages_;        // open sockets, oldest first
  int64_t controller_ = -1;        // the steering page's id (-1: none)
  int64_t control_since_ns_ = 0;   // when it got control
  int64_t session_ = 0;            // numbers each page's control (BrowserInput::session)
  int64_t fed_seq_ = -1;           // the newest seq whose input-to-force figure was taken
  int64_t messages_ = 0, ignored_ = 0, refused_ = 0, controllers_ = 0, takeovers_ = 0, evicted_ = 0;
  std::string last_refusal_;
  Controls controls_;              // the controls in force (the scene's own until the steering page changes them)
  int64_t control_changes_ = 0, control_refusals_ = 0;
  int64_t unheard_ = 0;            // a change the steering page has not acknowledged (its poses until then are not
                                   // passed on: they were made before the tool went back); 0: none
  std::string last_control_refusal_;
  std::string ended_;              // the run-ended message, once the run ended
  // the last kWindow figures of each latency (server: receipt to force, us; page: event to force / to frame, ms)
  static constexpr std::size_t kWindow = 600;
  std::deque<double> server_us_, page_force_ms_, page_frame_ms_;
};

/// Whether `query` ("a=1&token=abc") carries token=`token` exactly (compared in time independent of where they
/// differ). An empty token is never carried.
bool query_has_token(std::string_view query, std::string_view token);

}  // namespace palpate
