// The WebSocket half of HttpServer (RFC 6455): the upgrade's reply, and reading, writing and closing a socket on the
// server's loop. The request half is http_server.cpp.
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <string_view>

#include "core/clock.h"
#include "runtime/live/http_conn.h"
#include "runtime/live/http_server.h"
#include "runtime/live/sha1.h"

namespace palpate {

using http_detail::kDrain_ms;
using http_detail::kDrainBytes;
using http_detail::kMs;

bool loopback_host(std::string_view host) {
  // the name without its port ("[::1]:8080" keeps its brackets)
  std::string_view name = host;
  if (!name.empty() && name.front() == '[') {
    const auto close = name.find(']');
    if (close == std::string_view::npos) return false;
    if (close + 1 < name.size() && name[close + 1] != ':') return false;
    return name.substr(0, close + 1) == "[::1]";
  }
  if (const auto colon = name.find(':'); colon != std::string_view::npos) name = name.substr(0, colon);
  if (name.size() == 9) {
    std::string lower(name);
    for (char& c : lower) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    if (lower == "localhost") return true;
  }
  // 127.a.b.c, each part 0..255 in decimal
  if (name.substr(0, 4) != "127.") return false;
  int parts = 2, digits = 0, value = 0;  // "127" and the one being read
  for (char c : name.substr(4)) {
    if (c == '.') {
      if (digits == 0) return false;
      ++parts;
      digits = value = 0;
    } else if (c >= '0' && c <= '9' && digits < 3) {
      value = value * 10 + (c - '0');
      ++digits;
      if (value > 255) return false;
    } else {
      return false;
    }
  }
  return parts == 4 && digits > 0;
}

HttpReply websocket_upgrade(const HttpRequest& req, bool loopback_only) {
  HttpReply r;
  auto refuse = [&r](int status, const std::string& why) {
    r.status = status;
    r.content_type = "text/plain; charset=utf-8";
    r.body = std::make_shared<const std::string>(std::to_string(status) + " " + http_reason(status) + ": " + why + "\n");
    return r;
  };
  if (!req.upgrade_websocket) return refuse(400, "a WebSocket upgrade needs Connection: Upgrade and Upgrade: websocket");
  if (req.ws_version != "13") {
    r.headers.emplace_back("Sec-WebSocket-Version", "13");
    return refuse(426, "Sec-WebSocket-Version '" + req.ws_version + "' is not 13");
  }
  // 16 bytes in base64: 22 characters of the alphabet and "=="
  const std::string& k = req.ws_key;
  if (k.size() != 24 || k.compare(22, 2, "==") != 0 ||
      k.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/") != 22)
    return refuse(400, "Sec-WebSocket-Key is not 16 bytes in base64");
  if (!req.origin.empty() && req.origin != "http://" + req.host)
    return refuse(403, "Origin '" + req.origin + "' is not this server's page (http://" + req.host + ")");
  if (loopback_only && !loopback_host(req.host))
    return refuse(403, "Host '" + req.host + "' is not a loopback name: this server listens on loopback only, so its "
                       "page is http://localhost:PORT/ or http://127.0.0.1:PORT/ (also through an SSH tunnel)");
  r.status = 101;
  r.upgrade = true;
  r.headers.emplace_back("Upgrade", "websocket");
  r.headers.emplace_back("Connection", "Upgrade");
  r.headers.emplace_back("Sec-WebSocket-Accept", websocket_accept(k));
  return r;
}

HttpServer::Conn* HttpServer::socket(int64_t id) const {
  if (!conns_) return nullptr;
  for (const auto& c : *conns_)
    if (c->id == id && c->state == Conn::State::kSocket && !c->dead) return c.get();
  return nullptr;
}

bool HttpServer::ws_send(int64_t id, std::string_view text) {
  Conn* c = socket(id);
  if (!c || c->ws_closing) return false;
  const std::string frame = ws_encode_frame(WsOpcode::kText, text);
  if (c->ws_out.size() + frame.size() > limits_.ws_max_out_bytes) return false;
  if (c->ws_out.empty()) c->progress_ns = monotonic_ns();
  c->ws_out += frame;
  socket_write(c, monotonic_ns());
  return true;
}

void HttpServer::ws_close(int64_t id, uint16_t code, std::string_view reason) {
  if (Conn* c = socket(id); c && !c->ws_closing) socket_close(c, code, reason);
}

void HttpServer::socket_end(Conn* c, const std::string& why) {
  if (!c->ws_open) return;
  c->ws_open = false;
  sockets_.fetch_sub(1, std::memory_order_relaxed);
  if (ws_.close) ws_.close(c->id, why);
}

void HttpServer::socket_close(Conn* c, uint16_t code, std::string_view reason) {
  // the close frame goes out after what is queued; nothing is read or queued after it
  if (c->ws_out.empty()) c->progress_ns = monotonic_ns();
  c->ws_out += ws_encode_frame(WsOpcode::kClose, ws_close_payload(code, reason));
  c->ws_closing = true;
  c->in.clear();
  socket_end(c, std::string(reason));
  socket_write(c, monotonic_ns());
}

void HttpServer::socket_read(Conn* c, int64_t now_ns) {
  // an incomplete frame is always shorter than the largest frame allowed (ws_parse_frame refuses a longer one from
  // its header), so after the whole frames are handled there is room to read again; one call reads a bounded amount
  const std::size_t hold = 4 * ws_max_frame_bytes(limits_.ws);
  char buf[1024];
  std::size_t taken = 0;
  while (!c->ws_closing && !c->dead && taken < kDrainBytes) {
    // every whole frame received is handled; the idle deadline restarts at each
    for (;;) {
      WsParse p = ws_parse_frame(c->in, limits_.ws);
      if (p.kind == WsParse::Kind::kIncomplete) break;
      if (p.kind == WsParse::Kind::kError) {
        ws_refused_.fetch_add(1, std::memory_order_relaxed);
        socket_close(c, p.close_code, p.reason);
        return;
      }
      c->in.erase(0, p.consumed);
      c->deadline_ns = now_ns + limits_.ws_idle_timeout_ms * kMs;
      if (p.opcode == WsOpcode::kPing) {
        if (c->ws_out.size() + p.payload.size() + 4 <= limits_.ws_max_out_bytes) {
          if (c->ws_out.empty()) c->progress_ns = now_ns;
          c->ws_out += ws_encode_frame(WsOpcode::kPong, p.payload);
        }
      } else if (p.opcode == WsOpcode::kClose) {
        socket_close(c, kWsCloseNormal, "closed by the page");
        return;
      } else if (p.opcode != WsOpcode::kPong && ws_.message) {
        ws_.message(c->id, p.opcode, p.payload);
      }
      if (c->ws_closing || c->dead) return;  // closed by the callback
    }
    const std::size_t room = hold - std::min(c->in.size(), hold);
    const ssize_t n = ::recv(c->fd, buf, std::min(room, sizeof buf), 0);
    if (n > 0) {
      c->in.append(buf, static_cast<std::size_t>(n));
      taken += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    c->dead = true;  // closed by the page (a closed tab), or an error
    socket_end(c, "page gone");
    return;
  }
  if (!c->dead) socket_write(c, now_ns);
}

void HttpServer::socket_write(Conn* c, int64_t now_ns) {
  while (!c->ws_out.empty()) {
    const ssize_t w = ::send(c->fd, c->ws_out.data(), c->ws_out.size(), MSG_NOSIGNAL);
    if (w > 0) {
      c->ws_out.erase(0, static_cast<std::size_t>(w));
      c->progress_ns = now_ns;
      continue;
    }
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    c->dead = true;  // the loop ends the socket (its close callback runs there, never inside ws_send)
    return;
  }
  if (c->ws_closing) {
    // the close frame is out: the page's own close and anything else it sends is read and dropped, bounded
    ::shutdown(c->fd, SHUT_WR);
    c->state = Conn::State::kDraining;
    c->deadline_ns = now_ns + kDrain_ms * kMs;
  }
}

}  // namespace palpate
