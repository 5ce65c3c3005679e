#pragma once
/// HttpServer: a small event-driven HTTP/1.1 server for the live view. One thread runs a poll() loop over
/// non-blocking sockets, so a slow or silent client holds a connection slot, never a thread. Everything a client
/// can make it hold is bounded: the request head (HttpHeadLimits), no body at all, one reply in flight per
/// connection, a connection cap kept below the process's descriptor limit with descriptors reserved for the
/// recording, a deadline for a whole request head, for an idle keep-alive connection and for a reply, and a stop()
/// that waits for no client longer than the shutdown grace.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "core/result.h"
#include "tools/live/http_request.h"

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
};

/// A reply. wait = true defers it: the handler is asked again every few ms until it answers or must.
struct HttpReply {
  int status = 200;
  std::string content_type;                        ///< empty for no Content-Type (204)
  std::shared_ptr<const std::string> body;         ///< may be shared between connections; null = empty
  std::vector<std::pair<std::string, std::string>> headers;  ///< extra headers
  bool wait = false;                               ///< nothing to send yet (allowed only when !must_answer)
};

/// Answers a request; must_answer is true at the wait deadline and while stopping. Thread: the server's loop.
using HttpHandler = std::function<HttpReply(const HttpRequest& request, bool must_answer)>;

/// The server. Not copyable. Thread: start/stop from one controlling thread; handler and tick on the loop thread.
class HttpServer {
 public:
  /// handler answers every parsed request; tick (may be empty) runs about every tick_ms on the loop thread.
  HttpServer(HttpHandler handler, std::function<void()> tick, int64_t tick_ms, HttpLimits limits = {});
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
  std::atomic<int64_t> refused_{0}, timed_out_{0}, evicted_{0};
  std::thread thread_;
};

}  // namespace palpate
