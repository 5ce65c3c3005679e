#include "runtime/live/http_server.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>

#include "core/clock.h"
#include "runtime/live/http_conn.h"

namespace palpate {

using http_detail::kDrain_ms;
using http_detail::kDrainBytes;
using http_detail::kMs;

namespace {

// a parked reply is looked at again this often
constexpr int64_t kWaitPoll_ms = 10;
// at the connection cap, a connection that has waited this long for a request head gives its place to a new one:
// idle and half-sent connections cannot keep a well-behaved client out
constexpr int64_t kEvictAfter_ms = 10;
// connections the kernel completes and holds for accept(): a burst of junk connections does not fill it, so a
// well-behaved client's connection waits there (instead of its SYN being dropped and resent after 1 s, 3 s ...)
constexpr int kListenBacklog = 1024;

// descriptors open in this process now
int open_descriptors() {
  DIR* d = ::opendir("/proc/self/fd");
  if (!d) return 0;
  int n = 0;
  while (::readdir(d)) ++n;
  ::closedir(d);
  return n - 3;  // ".", ".." and the directory's own descriptor
}

}  // namespace

HttpServer::HttpServer(HttpHandler handler, std::function<void()> tick, int64_t tick_ms, HttpLimits limits)
    : handler_(std::move(handler)), tick_(std::move(tick)), tick_ms_(tick_ms), limits_(limits) {}

HttpServer::~HttpServer() {
  stop();
  if (listen_fd_ >= 0) ::close(listen_fd_);
  for (int fd : wake_)
    if (fd >= 0) ::close(fd);
}

Status HttpServer::start(const std::string& host, int port) {
  const std::string where = host + ":" + std::to_string(port);
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) return make_error("--serve ", where, ": cannot open a socket: ", std::strerror(errno));
  // SO_REUSEADDR alone: a port left in TIME_WAIT by the last run's browser is reused at once, while a port that
  // another process listens on is still refused
  const int yes = 1;
  ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(static_cast<uint16_t>(port));
  if (inet_pton(AF_INET, host.c_str(), &sa.sin_addr) != 1) return make_error("--serve ", where, ": not an IPv4 address");
  if (::bind(listen_fd_, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0 || ::listen(listen_fd_, kListenBacklog) != 0)
    return make_error("--serve ", where, ": cannot listen there: ", std::strerror(errno));
  socklen_t len = sizeof sa;
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&sa), &len);
  port_ = ntohs(sa.sin_port);
  if (::pipe2(wake_, O_NONBLOCK | O_CLOEXEC) != 0)
    return make_error("--serve ", where, ": cannot make a pipe: ", std::strerror(errno));
  // connections come out of what the descriptor limit leaves after what is open and what the recording keeps
  rlimit lim{};
  ::getrlimit(RLIMIT_NOFILE, &lim);
  const int64_t soft = lim.rlim_cur == RLIM_INFINITY ? INT32_MAX : static_cast<int64_t>(lim.rlim_cur);
  const int64_t room = soft - open_descriptors() - limits_.reserved_fds;
  cap_ = static_cast<int>(std::clamp<int64_t>(room, 0, limits_.max_connections));
  if (cap_ < 1)
    return make_error("--serve ", where, ": the descriptor limit (", std::to_string(soft), ", ulimit -n) leaves no room "
                      "for a connection beside the ", std::to_string(limits_.reserved_fds), " kept for the recording");
  thread_ = std::thread([this] {
    // out of memory (or any failure) in the view ends the view with a line, never the process and its recording
    // (the connections close with the loop's frame)
    try {
      loop();
    } catch (const std::exception& e) {
      open_.store(0, std::memory_order_relaxed);
      std::fprintf(stderr, "palpate: warning: the live view stopped serving: %s\n", e.what());
    }
  });
  return Ok{};
}

void HttpServer::stop() {
  if (!thread_.joinable()) return;
  stopping_.store(true);
  const char b = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &b, 1);
  thread_.join();
}

void HttpServer::loop() {
  // the view runs at nice 10: when the cores are short the recording's threads go first
  ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
  std::vector<std::unique_ptr<Conn>> conns;
  conns_ = &conns;
  std::vector<pollfd> pfds;
  std::vector<Conn*> polled;
  int64_t next_tick_ns = 0, stop_at_ns = 0;
  bool stop_seen = false;
  for (;;) {
    int64_t now = monotonic_ns();
    if (stopping_.load() && !stop_seen) {
      // no new request is read; replies waiting are made now; replies under way get the grace
      stop_seen = true;
      stop_at_ns = now + limits_.shutdown_grace_ms * kMs;
      for (auto& c : conns) {
        if (c->state == Conn::State::kReading || c->state == Conn::State::kDraining) c->dead = true;
        if (c->state == Conn::State::kSocket && !c->ws_closing) socket_close(c.get(), 1001, "server stopping");
        c->close_after = true;
      }
    }
    if (tick_ && now >= next_tick_ns) {
      tick_();
      next_tick_ns = now + tick_ms_ * kMs;
    }
    for (auto& c : conns)
      if (!c->dead && c->state == Conn::State::kWaiting) answer(c.get(), now, stop_seen || now >= c->deadline_ns);
    now = monotonic_ns();
    for (auto& c : conns) {
      if (c->dead) continue;
      const bool stalled = (c->state == Conn::State::kWriting ||
                            (c->state == Conn::State::kSocket && !c->ws_out.empty())) &&
                           now - c->progress_ns >= limits_.write_stall_ms * kMs;
      const bool late = (c->state != Conn::State::kWaiting && now >= c->deadline_ns) || stalled ||
                        (stop_seen && now >= stop_at_ns);
      if (late) {
        c->dead = true;
        if (c->state != Conn::State::kDraining) timed_out_.fetch_add(1, std::memory_order_relaxed);
      }
    }
    for (auto& c : conns)
      if (c->dead) socket_end(c.get(), "connection closed");
    conns.erase(std::remove_if(conns.begin(), conns.end(),
                               [this](const std::unique_ptr<Conn>& c) {
                                 if (!c->dead) return false;
                                 open_.fetch_sub(1, std::memory_order_relaxed);
                                 return true;
                               }),
                conns.end());
    if (stop_seen && conns.empty()) break;

    // what to wait for, and how long at most
    pfds.clear();
    polled.clear();
    pfds.push_back({wake_[0], POLLIN, 0});
    const bool accepting =
        !stop_seen && (static_cast<int>(conns.size()) < cap_ || evictable(conns, now) != nullptr);
    if (accepting) pfds.push_back({listen_fd_, POLLIN, 0});
    int64_t wake_at_ns = tick_ ? next_tick_ns : now + 1000 * kMs;
    if (stop_seen) wake_at_ns = std::min(wake_at_ns, stop_at_ns);
    for (auto& c : conns) {
      short events = 0;
      switch (c->state) {
        case Conn::State::kReading:
          events = POLLIN;
          // at the cap: awake when this one may give its place to a connection waiting to be accepted
          if (!accepting) wake_at_ns = std::min(wake_at_ns, c->reading_since_ns + kEvictAfter_ms * kMs);
          break;
        case Conn::State::kDraining: events = POLLIN; break;
        case Conn::State::kWriting:
          events = POLLOUT;
          wake_at_ns = std::min(wake_at_ns, c->progress_ns + limits_.write_stall_ms * kMs);
          break;
        case Conn::State::kWaiting: wake_at_ns = std::min(wake_at_ns, now + kWaitPoll_ms * kMs); break;
        case Conn::State::kSocket:
          events = c->ws_closing ? 0 : POLLIN;
          if (!c->ws_out.empty()) {
            events |= POLLOUT;
            wake_at_ns = std::min(wake_at_ns, c->progress_ns + limits_.write_stall_ms * kMs);
          }
          break;
      }
      wake_at_ns = std::min(wake_at_ns, c->deadline_ns);
      pfds.push_back({c->fd, events, 0});
      polled.push_back(c.get());
    }
    const int timeout_ms = static_cast<int>(std::clamp<int64_t>((wake_at_ns - now + kMs - 1) / kMs, 0, 1000));
    if (::poll(pfds.data(), pfds.size(), timeout_ms) < 0 && errno != EINTR) break;
    now = monotonic_ns();
    if (pfds[0].revents) {
      char buf[64];
      while (::read(wake_[0], buf, sizeof buf) > 0) {
      }
    }
    const std::size_t first = accepting ? 2 : 1;
    for (std::size_t i = first; i < pfds.size(); ++i) {
      Conn* c = polled[i - first];
      const short ev = pfds[i].revents;
      if (ev == 0 || c->dead) continue;
      if (ev & POLLNVAL) {
        c->dead = true;
      } else if (c->state == Conn::State::kSocket) {
        if (ev & POLLOUT) socket_write(c, now);
        if (!c->dead && c->state == Conn::State::kSocket && (ev & (POLLIN | POLLERR | POLLHUP))) socket_read(c, now);
      } else if (c->state == Conn::State::kWriting && (ev & (POLLOUT | POLLERR | POLLHUP))) {
        write_ready(c, now);
      } else if (ev & (POLLIN | POLLERR | POLLHUP)) {
        read_ready(c, now);
      }
    }
    if (accepting && pfds[1].revents) accept_ready(now, &conns);
  }
  for (auto& c : conns) socket_end(c.get(), "server stopped");
  conns_ = nullptr;
  open_.store(0, std::memory_order_relaxed);
}

HttpServer::Conn* HttpServer::evictable(const std::vector<std::unique_ptr<Conn>>& conns, int64_t now_ns) const {
  // a connection draining a refusal goes first, then the one waiting longest for a request head
  Conn* best = nullptr;
  for (const auto& c : conns) {
    if (c->dead) continue;
    if (c->state == Conn::State::kDraining) return c.get();
    if (c->state == Conn::State::kReading && now_ns - c->reading_since_ns >= kEvictAfter_ms * kMs &&
        (!best || c->reading_since_ns < best->reading_since_ns))
      best = c.get();
  }
  return best;
}

void HttpServer::accept_ready(int64_t now_ns, std::vector<std::unique_ptr<Conn>>* conns) {
  int live = 0;
  for (const auto& c : *conns) live += c->dead ? 0 : 1;
  for (;;) {
    Conn* victim = nullptr;
    if (live >= cap_) {
      victim = evictable(*conns, now_ns);
      if (!victim) return;
    }
    auto c = std::make_unique<Conn>();
    c->fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (c->fd < 0) return;  // none waiting, or no descriptor now (the next loop tries again)
    if (victim) {
      // its descriptor is given back at once, so the cap holds within this loop too
      ::close(victim->fd);
      victim->fd = -1;
      victim->dead = true;
      evicted_.fetch_add(1, std::memory_order_relaxed);
      --live;
    }
    ++live;
    c->id = next_id_++;
    c->reading_since_ns = now_ns;
    const int yes = 1;
    ::setsockopt(c->fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof yes);
    c->deadline_ns = now_ns + limits_.head_timeout_ms * kMs;
    conns->push_back(std::move(c));
    open_.fetch_add(1, std::memory_order_relaxed);
  }
}

void HttpServer::read_ready(Conn* c, int64_t now_ns) {
  char buf[4096];
  for (;;) {
    std::size_t want = sizeof buf;
    if (c->state == Conn::State::kReading) {
      // never more than the head limit held: a longer head is refused, whatever follows stays unread
      const std::size_t room = limits_.head.max_head_bytes - std::min(c->in.size(), limits_.head.max_head_bytes);
      if (room == 0) break;
      want = std::min(want, room);
    } else if (c->state != Conn::State::kDraining) {
      return;
    }
    const ssize_t n = ::recv(c->fd, buf, want, 0);
    if (n > 0) {
      if (c->state == Conn::State::kDraining) {
        c->drained += static_cast<std::size_t>(n);
        if (c->drained >= kDrainBytes) c->dead = true;
        if (c->dead) return;
      } else {
        c->in.append(buf, static_cast<std::size_t>(n));
      }
      if (static_cast<std::size_t>(n) < want) break;
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) break;
    c->dead = true;  // closed by the client, or an error
    return;
  }
  parse(c, now_ns);
}

void HttpServer::parse(Conn* c, int64_t now_ns) {
  if (c->state != Conn::State::kReading || c->dead) return;
  const int64_t end = http_head_end(c->in, limits_.head);
  if (end == 0) return;
  HttpHeadParse p;
  if (end < 0) {
    p.status = static_cast<int>(-end);
    p.reason = p.status == 414 ? "request line over " + std::to_string(limits_.head.max_line_bytes) + " bytes"
                               : "request head over " + std::to_string(limits_.head.max_head_bytes) + " bytes";
  } else {
    p = parse_http_head(std::string_view(c->in).substr(0, static_cast<std::size_t>(end)), limits_.head);
    c->in.erase(0, static_cast<std::size_t>(end));
  }
  if (p.status != 0) {
    refused_.fetch_add(1, std::memory_order_relaxed);
    c->in.clear();
    HttpReply r;
    r.status = p.status;
    r.content_type = "text/plain; charset=utf-8";
    r.body = std::make_shared<const std::string>(std::to_string(p.status) + " " + http_reason(p.status) + ": " +
                                                 p.reason + "\n");
    if (p.status == 405) r.headers.emplace_back("Allow", "GET, HEAD");
    queue_reply(c, r, false, false, now_ns);
    return;
  }
  c->request = std::move(p.request);
  c->state = Conn::State::kWaiting;
  c->deadline_ns = now_ns + limits_.max_wait_ms * kMs;
  answer(c, now_ns, stopping_.load());
}

void HttpServer::answer(Conn* c, int64_t now_ns, bool must) {
  HttpReply r;
  try {
    r = handler_(c->request, must);
  } catch (const std::exception& e) {
    // out of memory or any failure in a handler costs this reply, never the process
    r = HttpReply{};
    r.status = 503;
    r.content_type = "text/plain; charset=utf-8";
    r.body = std::make_shared<const std::string>(std::string("503 Service Unavailable: ") + e.what() + "\n");
  }
  if (r.wait && !must) return;
  if (r.wait) r.status = 503;
  if (r.upgrade && ws_.message && ws_.evict && sockets_.load() >= limits_.max_sockets && !stopping_.load()) {
    // every slot is taken: the application may give one up (an idle page) for the new one
    const int64_t id = ws_.evict();
    if (Conn* old = id >= 0 ? socket(id) : nullptr; old && !old->ws_closing)
      socket_close(old, kWsClosePolicy, "a newer page took the slot of this one, idle longest");
  }
  if (r.upgrade && (!ws_.message || sockets_.load() >= limits_.max_sockets || stopping_.load())) {
    r = HttpReply{};
    r.status = 503;
    r.content_type = "text/plain; charset=utf-8";
    r.body = std::make_shared<const std::string>("503 Service Unavailable: " + std::to_string(limits_.max_sockets) +
                                                 " live sockets are open already\n");
  }
  queue_reply(c, r, c->request.method == "HEAD", c->request.keep_alive && !c->close_after && !stopping_.load(), now_ns);
}

void HttpServer::queue_reply(Conn* c, const HttpReply& r, bool head_only, bool keep_alive, int64_t now_ns) {
  const std::size_t body = r.body ? r.body->size() : 0;
  std::string h = "HTTP/1.1 " + std::to_string(r.status) + " " + http_reason(r.status) + "\r\n";
  if (r.upgrade) {
    // a 101 has no body; the connection is the WebSocket's once it is sent
    for (const auto& [k, v] : r.headers) h += k + ": " + v + "\r\n";
    c->out_head = h + "\r\n";
    c->out_body = nullptr;
    c->sent = 0;
    c->close_after = false;
    c->upgrade_after = true;
    c->state = Conn::State::kWriting;
    c->progress_ns = now_ns;
    c->deadline_ns = now_ns + limits_.write_timeout_ms * kMs;
    write_ready(c, now_ns);
    return;
  }
  if (!r.content_type.empty()) h += "Content-Type: " + r.content_type + "\r\n";
  h += "Content-Length: " + std::to_string(body) + "\r\n";
  for (const auto& [k, v] : r.headers) h += k + ": " + v + "\r\n";
  h += keep_alive ? "Connection: keep-alive\r\n\r\n" : "Connection: close\r\n\r\n";
  c->out_head = std::move(h);
  c->out_body = head_only ? nullptr : r.body;
  c->sent = 0;
  c->close_after = !keep_alive;
  c->state = Conn::State::kWriting;
  c->progress_ns = now_ns;
  c->deadline_ns = now_ns + limits_.write_timeout_ms * kMs;
  write_ready(c, now_ns);
}

void HttpServer::write_ready(Conn* c, int64_t now_ns) {
  const std::size_t body = c->out_body ? c->out_body->size() : 0;
  const std::size_t total = c->out_head.size() + body;
  while (c->sent < total) {
    const bool in_head = c->sent < c->out_head.size();
    const char* p = in_head ? c->out_head.data() + c->sent : c->out_body->data() + (c->sent - c->out_head.size());
    const std::size_t n = in_head ? c->out_head.size() - c->sent : total - c->sent;
    const ssize_t w = ::send(c->fd, p, n, MSG_NOSIGNAL);
    if (w > 0) {
      c->sent += static_cast<std::size_t>(w);
      c->progress_ns = now_ns;
      continue;
    }
    if (w < 0 && errno == EINTR) continue;
    if (w < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    c->dead = true;
    return;
  }
  c->out_head.clear();
  c->out_body.reset();
  if (c->upgrade_after) {
    c->upgrade_after = false;
    c->state = Conn::State::kSocket;
    c->ws_open = true;
    sockets_.fetch_add(1, std::memory_order_relaxed);
    c->deadline_ns = now_ns + limits_.ws_idle_timeout_ms * kMs;
    if (ws_.open) ws_.open(c->id, c->request);
    if (!c->in.empty()) socket_read(c, now_ns);  // frames sent right behind the request
    return;
  }
  if (c->close_after) {
    // the reply is out: read what the client still sends (bounded) until it closes, then close
    ::shutdown(c->fd, SHUT_WR);
    c->state = Conn::State::kDraining;
    c->deadline_ns = now_ns + kDrain_ms * kMs;
    if (stopping_.load()) c->dead = true;
    return;
  }
  c->state = Conn::State::kReading;
  c->reading_since_ns = now_ns;
  c->deadline_ns = now_ns + limits_.idle_timeout_ms * kMs;
  parse(c, now_ns);  // a request sent behind the last one
}

}  // namespace palpate
