#pragma once
/// HttpServer: a small event-driven HTTP/1.1 server for the live view. One thread runs a poll() loop over
/// non-blocking sockets, so a slow or silent client holds a connection slot, never a thread. Everything a client
/// can make it hold is bounded: the request head (HttpHeadLimits), no body at all, one reply in flight per
/// connection, a connection cap kept below the process's descriptor limit with descriptors reserved for the
/// recording, a deadline for a whole request head, for an idle keep-alive connection and for a reply, and a stop()
/// that waits for no client longer than the shutdown grace. A request may be upgraded to a WebSocket (RFC 6455):
/// the socket then carries small masked frames (WsLimits) on the same loop, with its own idle deadline, a bounded
/// outgoing buffer and a cap on open sockets; a frame that breaks a rule closes it.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "core/result.h"
#include "runtime/live/http_request.h"
#include "runtime/live/ws_frame.h"

namespace palpate {

/// Bounds and deadlines of an HttpServer. Plain data.
struct HttpLimits {
  HttpHeadLimits head;                     ///< request line, header count, head size
  int max_connections = 32;                ///< open connections at most (lower when descriptors are short)
  int reserved_fds = 64;                   ///< descriptors left to the rest of the process (frame files, log, video)
  int64_t head_timeout_ms = 5000;          ///< a whole request head must arrive within this (slow senders)
  int64_t idle_timeout_ms = 5000;          ///< a kept-alive connection with no request is closed after this
  int64_t write_stall_ms = 2000;           ///< a reply that makes no progress this long is dropped
  int64_t write_timeout_ms = 10000;        ///< a whole reply must be written within this
  int64_t max_wait_ms = 1000;              ///< a handler may defer its reply this long (long-poll)
  int64_t shutdown_grace_ms = 500;         ///< stop() waits at most this for replies under way
  WsLimits ws;                             ///< frames a WebSocket client may send
  int max_sockets = 4;                     ///< open WebSockets at most (further upgrades get 503, unless the
                                           ///< WsCallbacks' evict gives one up)
  int64_t ws_idle_timeout_ms = 10000;      ///< a WebSocket with no frame from the client this long is closed
  std::size_t ws_max_out_bytes = 65536;    ///< a WebSocket's unsent output at most (ws_send refuses beyond)
};

/// A reply. wait = true defers it: the handler is asked again every few ms until it answers or must.
struct HttpReply {
  int status = 200;
  std::string content_type;                        ///< empty for no Content-Type (204)
  std::shared_ptr<const std::string> body;         ///< may be shared between connections; null = empty
  std::vector<std::pair<std::string, std::string>> headers;  ///< extra headers
  bool wait = false;                               ///< nothing to send yet (allowed only when !must_answer)
  bool upgrade = false;                            ///< a 101 that turns the connection into a WebSocket
};

/// The reply to a WebSocket upgrade request (RFC 6455 §4.2.2): 101 with Sec-WebSocket-Accept, or 400 (not an upgrade,
/// a key that is not 16 bytes in base64), 426 (a version other than 13) or 403 (an Origin that is not this server's
/// own, i.e. not "http://" + Host: a page from another site may not steer the device; with loopback_only, also a
/// Host that is not a loopback name: a page of another site whose name was pointed at 127.0.0.1, DNS rebinding).
HttpReply websocket_upgrade(const HttpRequest& request, bool loopback_only = false);

/// True when a Host header names this machine's loopback: localhost, 127.x.x.x or [::1], with or without a port.
bool loopback_host(std::string_view host);

/// What a server does with its WebSockets. Each callback runs on the server's loop thread; any may be empty.
struct WsCallbacks {
  std::function<void(int64_t id, const HttpRequest& request)> open;      ///< a socket opened (after its 101)
  std::function<void(int64_t id, WsOpcode opcode, std::string_view payload)> message;  ///< a text or binary frame
  std::function<void(int64_t id, const std::string& why)> close;        ///< a socket ended, once, whatever ended it
  /// every socket slot is taken and a page asks for one: the socket to close for it (-1: none; the page gets 503)
  std::function<int64_t()> evict;
};

/// Answers a request; must_answer is true at the wait deadline and while stopping. Thread: the server's loop.
using HttpHandler = std::function<HttpReply(const HttpRequest& request, bool must_answer)>;

/// The server. Not copyable. Thread: start/stop from one controlling thread; handler and tick on the loop thread.
class HttpServer {
 public:
  /// handler answers every parsed request; tick (may be empty) runs about every tick_ms on the loop thread.
  HttpServer(HttpHandler handler, std::function<void()> tick, int64_t tick_ms, HttpLimits limits = {});
  /// The WebSocket callbacks (before start()).
  void set_websocket(WsCallbacks callbacks) { ws_ = std::move(callbacks); }
  /// Queues a text frame on socket `id`; false when the socket is gone or closing, or its unsent output would pass
  /// ws_max_out_bytes (the frame is dropped). Thread: the loop (callbacks, tick, handler).
  bool ws_send(int64_t id, std::string_view text);
  /// Closes socket `id` with a close frame (code, reason). Thread: the loop.
  void ws_close(int64_t id, uint16_t code, std::string_view reason);
  /// WebSockets open now (any thread).
  int sockets() const { return sockets_.load(std::memory_order_relaxed); }
  /// WebSockets closed for a frame that broke a rule (any thread).
  int64_t ws_refused() const { return ws_refused_.load(std::memory_order_relaxed); }
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  /// Binds host:port (IPv4, port 0 = any free port) with SO_REUSEADDR and starts the loop. Errors name the
  /// address and the system's reason, or the descriptor limit that leaves no room for connections.
  Status start(const std::string& host, int port);
  /// The port listened on.
  int port() const { return port_; }
  /// Connections the descriptor limit allows (min of max_connections and the limit less what is open and
  /// reserved); valid after start().
  int connection_cap() const { return cap_; }
  /// Connections open now (any thread).
  int connections() const { return open_.load(std::memory_order_relaxed); }
  /// Requests refused (4xx/5xx from the parser) and connections closed at a deadline (any thread).
  int64_t refused() const { return refused_.load(std::memory_order_relaxed); }
  int64_t timed_out() const { return timed_out_.load(std::memory_order_relaxed); }
  /// Connections closed at the cap to make room for a new one: those waiting longest for a request head (any thread).
  int64_t evicted() const { return evicted_.load(std::memory_order_relaxed); }
  /// Answers waiting replies, finishes replies under way for at most the shutdown grace, closes every
  /// connection and joins the loop; idempotent.
  void stop();

 private:
  struct Conn;
  void loop();
  void accept_ready(int64_t now_ns, std::vector<std::unique_ptr<Conn>>* conns);
  Conn* evictable(const std::vector<std::unique_ptr<Conn>>& conns, int64_t now_ns) const;
  void read_ready(Conn* c, int64_t now_ns);
  void parse(Conn* c, int64_t now_ns);
  void answer(Conn* c, int64_t now_ns, bool must);
  void queue_reply(Conn* c, const HttpReply& reply, bool head_only, bool keep_alive, int64_t now_ns);
  void write_ready(Conn* c, int64_t now_ns);
  void socket_read(Conn* c, int64_t now_ns);
  void socket_write(Conn* c, int64_t now_ns);
  void socket_end(Conn* c, const std::string& why);
  void socket_close(Conn* c, uint16_t code, std::string_view reason);
  Conn* socket(int64_t id) const;

  HttpHandler handler_;
  std::function<void()> tick_;
  int64_t tick_ms_;
  HttpLimits limits_;
  int listen_fd_ = -1;
  int wake_[2] = {-1, -1};
  int port_ = 0;
  int cap_ = 0;
  std::atomic<bool> stopping_{false};
  std::atomic<int> open_{0};
  std::atomic<int64_t> refused_{0}, timed_out_{0}, evicted_{0}, ws_refused_{0};
  std::atomic<int> sockets_{0};
  WsCallbacks ws_;
  int64_t next_id_ = 1;
  std::vector<std::unique_ptr<Conn>>* conns_ = nullptr;  // the loop's connections (loop thread only)
  std::thread thread_;
};

}  // namespace palpate
