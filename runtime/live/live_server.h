#pragma once
/// LiveServer: the live view of a recording over HTTP. Serves one self-contained page ("/"), the newest frame
/// as PNG ("/frame.png?after=N", long-polled) and the figures and plot points as JSON ("/stats.json?since=S").
/// Reads only the LiveFeed; runs on one event-driven thread (HttpServer, nice 10) that encodes the PNG. What a
/// client can make it hold is bounded (request head, no body, connections under the descriptor limit with the
/// recording's own descriptors reserved, deadlines; see HttpLimits), so no client costs the recording anything.

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "core/result.h"
#include "core/scene.h"
#include "haptics/devices/browser_link.h"
#include "runtime/live/live_feed.h"

namespace palpate {

/// Where to listen: an IPv4 address and a port (0 = any free port).
struct ServeAddress {
  std::string host = "127.0.0.1";
  int port = 0;
};

/// Whether a request's Host may reach a server bound to `bind_host`: on loopback, a loopback name (localhost,
/// 127.x.x.x, [::1]); on any other bind also an IP address literal or this machine's own name (`machine`, as
/// gethostname gives it, or its first label). Any other name is a page of another site whose name was pointed at
/// this machine (DNS rebinding), refused on every bind.
bool host_allowed(std::string_view host, std::string_view bind_host, std::string_view machine);

/// Parses "[ADDR:]PORT" (ADDR an IPv4 address or "localhost", default 127.0.0.1; PORT 0..65535, 0 = any free
/// port). Errors name the text and what is wrong with it.
Result<ServeAddress> parse_serve_address(const std::string& text);

/// The HTTP server of a live view. Not copyable. Thread: start/stop from one controlling thread.
class LiveServer {
 public:
  /// feed must outlive the server. browser (may be null): the page steers the device through it over a WebSocket at
  /// /ws (the first page to connect controls, later ones watch; a page that leaves or sends garbage releases it);
  /// it must outlive the server.
  explicit LiveServer(LiveFeed* feed, BrowserLink* browser = nullptr);
  ~LiveServer();
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  /// Binds and starts serving; errors name the address and the cause ("address in use", ...). A bind that is not
  /// loopback makes a random token: only a page opened with it (url()) may steer a browser device.
  Status start(const ServeAddress& address);
  /// The browser device's timing (its watchdog and the page's send interval; the defaults are the default scene's):
  /// set before start().
  void set_browser_timing(double stale_ms, double send_ms);
  /// The scene the steering page's controls are checked against (must outlive the server; null: no controls): set
  /// before start().
  void set_browser_scene(const Scene* scene);
  /// The page's address, e.g. "http://127.0.0.1:8080/", with "?token=..." when the server has a token (valid after
  /// start()).
  std::string url() const;
  /// The token a page needs to steer ("" on loopback, where any page of this server's own origin may).
  const std::string& token() const;
  /// The port listened on (the one chosen when 0 was asked).
  int port() const;
  /// Stops listening, ends the open connections (waiting at most HttpLimits::shutdown_grace_ms for replies under
  /// way) and joins the thread; idempotent.
  void stop();
  /// Connections the descriptor limit leaves room for (valid after start()).
  int connection_cap() const;
  /// Connections open now (any thread).
  int connections() const;
  /// WebSockets open now (any thread).
  int sockets() const;

  /// Frames sent so far (any thread).
  int64_t frames_sent() const;
  /// PNG frames encoded so far (any thread).
  int64_t frames_encoded() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// What the live page does, without a browser: long-polls /frame.png on one connection and reads /stats.json
/// four times a second on another, until destroyed. For measuring what a watched recording costs.
class LivePageClient {
 public:
  /// Starts fetching from 127.0.0.1:port.
  explicit LivePageClient(int port);
  ~LivePageClient();
  LivePageClient(const LivePageClient&) = delete;
  LivePageClient& operator=(const LivePageClient&) = delete;
  /// Frames received so far (any thread).
  int64_t frames() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The live page: HTML with inline script and style, nothing fetched from elsewhere.
const std::string& live_page_html();

}  // namespace palpate
