#pragma once
/// The HTTP server's connection record and the timings both halves of the server use (http_server.cpp: requests;
/// http_server_ws.cpp: WebSockets). Private to runtime/live.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "runtime/live/http_server.h"

namespace palpate::http_detail {

inline constexpr int64_t kMs = 1'000'000;
/// After a refused request or a closed socket: the client's further bytes are read and thrown away up to this much,
/// this long, so the refusal reaches it before the connection closes (a close with unread data resets it).
inline constexpr std::size_t kDrainBytes = 65536;
inline constexpr int64_t kDrain_ms = 1000;

}  // namespace palpate::http_detail

namespace palpate {

/// One client connection: its state, what was received and what is left to send. Thread: the server's loop.
struct HttpServer::Conn {
  enum class State { kReading, kWaiting, kWriting, kDraining, kSocket };
  int fd = -1;
  int64_t id = 0;
  State state = State::kReading;
  std::string in;                          // received, not yet parsed (at most the head limit)
  HttpRequest request;                     // the request being answered
  std::string out_head;                    // the reply's status line and headers
  std::shared_ptr<const std::string> out_body;
  std::size_t sent = 0;
  std::size_t drained = 0;
  bool close_after = false;
  bool dead = false;
  int64_t deadline_ns = 0;                 // reading: head/idle; waiting: must answer; writing/draining: whole
  int64_t progress_ns = 0;                 // writing: last byte sent
  int64_t reading_since_ns = 0;            // reading: when it began to wait for this request head
  bool upgrade_after = false;              // the reply under way is a 101: a WebSocket after it
  bool ws_open = false;                    // a WebSocket whose close callback has not run yet
  bool ws_closing = false;                 // its close frame is queued: nothing more is read or sent
  std::string ws_out;                      // a WebSocket's frames not yet sent
  ~Conn() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace palpate
