#include "runtime/live/live_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/random.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <deque>
#include <thread>

#include <httplib.h>
#include <png.h>
#include <zlib.h>

#include <nlohmann/json.hpp>

#include "core/clock.h"
#include "runtime/live/browser_control.h"
#include "runtime/live/http_server.h"

namespace palpate {
namespace {

// the feed's points and figures are taken this often (the feed's queue holds ~8 s of points)
constexpr int64_t kCollect_ms = 100;
// with a browser device the loop ticks this often, to send the pages the device force
constexpr int64_t kFeedback_ms = 16;
// after a frame request the sim thread keeps copying frames this long
constexpr int64_t kWantFrames_ns = 3'000'000'000;
// plot points kept for /stats.json (10 minutes at 60 Hz) and sent in one reply at most
constexpr std::size_t kHistoryPoints = 36'000;
constexpr std::size_t kPointsPerReply = 3'600;

// PNG of an RGBA frame in memory, with the frame writer's fast settings
bool encode_png(int width, int height, const uint8_t* rgba, std::string* out) {
  out->clear();
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, info ? &info : nullptr);
    return false;
  }
  png_set_write_fn(
      png, out,
      [](png_structp p, png_bytep data, png_size_t n) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), n);
      },
      nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGBA,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 1);
  png_set_compression_strategy(png, Z_RLE);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y)
    png_write_row(png, const_cast<png_bytep>(rgba + static_cast<std::size_t>(y) * static_cast<std::size_t>(width) * 4));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

// 16 random bytes as 32 hex digits (the kernel's generator); "" when it cannot give them
std::string random_token() {
  unsigned char b[16];
  std::size_t got = 0;
  while (got < sizeof b) {
    const ssize_t n = ::getrandom(b + got, sizeof b - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return {};
    got += static_cast<std::size_t>(n);
  }
  static const char* hex = "0123456789abcdef";
  std::string t;
  for (unsigned char c : b) {
    t += hex[c >> 4];
    t += hex[c & 15];
  }
  return t;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
  return out;
}

}  // namespace

bool host_allowed(std::string_view host, std::string_view bind_host, std::string_view machine) {
  if (loopback_host(host)) return true;
  if (bind_host.substr(0, 4) == "127.") return false;
  // the name without its port
  std::string_view name = host;
  if (!name.empty() && name.front() == '[') {
    const auto close = name.find(']');
    if (close == std::string_view::npos || (close + 1 < name.size() && name[close + 1] != ':')) return false;
    const std::string inner(name.substr(1, close - 1));
    in6_addr a6{};
    return inet_pton(AF_INET6, inner.c_str(), &a6) == 1;
  }
  if (const auto colon = name.find(':'); colon != std::string_view::npos) name = name.substr(0, colon);
  if (name.empty()) return false;
  in_addr a4{};
  if (inet_pton(AF_INET, std::string(name).c_str(), &a4) == 1) return true;
  if (machine.empty()) return false;
  const std::string n = lower(name), m = lower(machine);
  return n == m || n == m.substr(0, m.find('.'));
}

Result<ServeAddress> parse_serve_address(const std::string& text) {
  ServeAddress a;
  std::string port = text;
  const auto colon = text.rfind(':');
  if (colon != std::string::npos) {
    a.host = text.substr(0, colon);
    port = text.substr(colon + 1);
    if (a.host == "localhost") a.host = "127.0.0.1";
    in_addr probe{};
    if (a.host.empty() || inet_pton(AF_INET, a.host.c_str(), &probe) != 1)
      return make_error("--serve '", text, "': '", a.host, "' is not an IPv4 address (e.g. 127.0.0.1 or 0.0.0.0)");
  }
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoi(port) > 65535)
    return make_error("--serve '", text, "': port '", port, "' is not a number from 0 to 65535");
  a.port = std::stoi(port);
  return a;
}

struct LiveServer::Impl {
  Impl(LiveFeed* f, BrowserLink* l)
      : feed(f),
        link(l), http([this](const HttpRequest& r, bool must) { return answer(r, must); }, [this] { tick(); },
                      l ? kFeedback_ms : kCollect_ms) {
  }

  LiveFeed* feed;
  BrowserLink* link;
  HttpServer http;
  std::unique_ptr<BrowserControl> browser;
  BrowserControlParams browser_params;  // set_browser_timing()'s (the token is added at start)
  int64_t next_collect_ns = 0;
  std::string host;
  int port = 0;
  bool loopback_only = false;  // set before the loop starts: the socket's Host must name loopback (DNS rebinding)
  std::string machine;         // this machine's name (a Host a bind beyond loopback accepts)
  std::string token;           // a bind beyond loopback: what a page needs to steer
  bool ended_sent = false;

  // everything below is the server loop's own (one thread): no locks
  // plot points taken from the feed: points [history_begin, history_begin + history.size())
  std::deque<LivePoint> history;
  int64_t history_begin = 0;
  std::vector<LivePoint> scratch;
  LiveFigures figures;
  // the newest frame as PNG, shared by every client asking for it
  std::vector<uint8_t> rgba;
  int64_t png_index = -1;
  std::shared_ptr<const std::string> png;
  const std::shared_ptr<const std::string> page = std::make_shared<const std::string>(live_page_html());

  std::atomic<int64_t> frames_sent{0}, frames_encoded{0};

  // the loop's tick: the pages' force (every kFeedback_ms) and the feed's points (every kCollect_ms)
  void tick() {
    if (browser) browser->tick(feed->frame_index());
    if (browser && !ended_sent && figures.finished) {
      ended_sent = true;
      browser->run_ended(feed->out_dir());
    }
    const int64_t now = monotonic_ns();
    if (now < next_collect_ns) return;
    next_collect_ns = now + kCollect_ms * 1'000'000;
    collect();
  }

  // takes the feed's new points and figures (every kCollect_ms and every /stats.json)
  void collect() {
    scratch.clear();
    feed->take_points(&scratch);
    figures = feed->figures();
    for (const LivePoint& p : scratch) history.push_back(p);
    while (history.size() > kHistoryPoints) {
      history.pop_front();
      ++history_begin;
    }
  }

  // the newest frame encoded, when newer than `after` (nullptr otherwise)
  std::shared_ptr<const std::string> newest_png(int64_t after, int64_t* index) {
    if (feed->frame_index() > png_index) {
      const int64_t got = feed->copy_frame(png_index, &rgba);
      if (got >= 0) {
        auto s = std::make_shared<std::string>();
        if (encode_png(feed->width(), feed->height(), rgba.data(), s.get())) {
          png = std::move(s);
          png_index = got;
          frames_encoded.fetch_add(1, std::memory_order_relaxed);
        }
      }
    }
    *index = png_index;
    return png_index > after ? png : nullptr;
  }

  HttpReply answer(const HttpRequest& req, bool must) {
    HttpReply r;
    r.headers.emplace_back("Cache-Control", "no-store");
    if (!req.host.empty() && !host_allowed(req.host, host, machine)) {
      // a name of another site pointed at this machine (DNS rebinding): nothing is served to it
      r.status = 403;
      r.content_type = "text/plain; charset=utf-8";
      r.body = std::make_shared<const std::string>(
          "403 Forbidden: Host '" + req.host.substr(0, 200) + "' is not a name of this server (" +
          (loopback_only ? std::string("localhost or 127.0.0.1") : "an IP address, localhost or " + machine) + ")\n");
      return r;
    }
    if (req.path == "/") {
      r.content_type = "text/html; charset=utf-8";
      r.body = page;
    } else if (req.path == "/frame.png") {
      // long poll: the reply waits (up to the server's max_wait) for a frame newer than the client's
      const int64_t after = query_int(req.query, "after", -1);
      feed->want_frames_until(monotonic_ns() + kWantFrames_ns);
      int64_t index = -1;
      if (auto p = newest_png(after, &index)) {
        r.content_type = "image/png";
        r.body = std::move(p);
        frames_sent.fetch_add(1, std::memory_order_relaxed);
      } else if (!must) {
        r.wait = true;
      } else {
        r.status = 204;  // nothing newer: the client asks again
      }
      r.headers.emplace_back("X-Frame", std::to_string(index));
    } else if (req.path == "/ws" && browser) {
      return websocket_upgrade(req, loopback_only);
    } else if (req.path == "/stats.json") {
      r.content_type = "application/json";
      r.body = std::make_shared<const std::string>(stats(query_int(req.query, "since", 0)));
    } else {
      r.status = 404;
      r.content_type = "text/plain; charset=utf-8";
      r.body = std::make_shared<const std::string>("404 Not Found: the live view serves /, /frame.png and /stats.json\n");
    }
    return r;
  }

  std::string stats(int64_t since) {
    collect();
    nlohmann::json j;
    const LiveFigures& f = figures;
    j["scene"] = feed->scene();
    j["mode"] = feed->mode();
    j["out"] = feed->out_dir();
    j["width"] = feed->width();
    j["height"] = feed->height();
    j["finished"] = f.finished;
    j["t_s"] = f.t_s;
    j["frames"] = f.frames;
    j["frames_written"] = f.frames_written;
    j["frames_dropped"] = f.frames_dropped;
    j["frames_late"] = f.frames_late;
    j["max_force_N"] = f.max_force_N;
    j["servo"] = {{"ticks", f.servo_ticks}, {"overruns", f.overruns}, {"p50_us", f.servo_p50_us},
                  {"p99_us", f.servo_p99_us}};
    j["frame"] = feed->frame_index();
    j["points_dropped"] = feed->points_dropped();
    if (browser) j["browser"] = browser->stats();
    since = std::clamp<int64_t>(since, history_begin, history_begin + static_cast<int64_t>(history.size()));
    const auto first = static_cast<std::size_t>(since - history_begin);
    const std::size_t n = std::min(history.size() - first, kPointsPerReply);
    nlohmann::json frame = nlohmann::json::array(), t = nlohmann::json::array(), force = nlohmann::json::array(),
                   contact = nlohmann::json::array(), wake = nlohmann::json::array(),
                   work = nlohmann::json::array(), late = nlohmann::json::array();
    for (std::size_t i = first; i < first + n; ++i) {
      const LivePoint& p = history[i];
      frame.push_back(p.frame);
      t.push_back(p.t_s);
      force.push_back(p.force_N);
      contact.push_back(p.contact);
      wake.push_back(p.wake_max_us);
      work.push_back(p.frame_ms);
      late.push_back(p.late_ms);
    }
    j["points"] = {{"from", since},      {"frame", frame},       {"t_s", t},          {"force_N", force},
                   {"contact", contact}, {"wake_max_us", wake}, {"frame_ms", work}, {"late_ms", late}};
    j["next"] = since + static_cast<int64_t>(n);
    return j.dump();
  }
};

LiveServer::LiveServer(LiveFeed* feed, BrowserLink* browser) : impl_(std::make_unique<Impl>(feed, browser)) {}

LiveServer::~LiveServer() { stop(); }

void LiveServer::set_browser_timing(double stale_ms, double send_ms) {
  impl_->browser_params.stale_ms = stale_ms;
  impl_->browser_params.send_ms = send_ms;
}

void LiveServer::set_browser_scene(const Scene* scene) { impl_->browser_params.scene = scene; }

Status LiveServer::start(const ServeAddress& address) {
  Impl& m = *impl_;
  m.loopback_only = address.host.rfind("127.", 0) == 0;
  m.host = address.host;
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) == 0) m.machine = name;
  if (!m.loopback_only) {
    m.token = random_token();
    if (m.token.empty()) return make_error("--serve ", address.host, ": no random token for a bind beyond loopback (",
                                           std::strerror(errno), ")");
  }
  if (m.link) {
    BrowserControlParams p = m.browser_params;
    p.token = m.token;
    m.browser = std::make_unique<BrowserControl>(&m.http, m.link, p);
  }
  if (auto st = m.http.start(address.host, address.port); !st) return st;
  m.port = m.http.port();
  return Ok{};
}

std::string LiveServer::url() const {
  const std::string host = impl_->host == "0.0.0.0" ? "127.0.0.1" : impl_->host;
  return "http://" + host + ":" + std::to_string(impl_->port) + "/" + (impl_->token.empty() ? "" : "?token=" + impl_->token);
}

const std::string& LiveServer::token() const { return impl_->token; }

int LiveServer::port() const { return impl_->port; }

void LiveServer::stop() { impl_->http.stop(); }

int LiveServer::connection_cap() const { return impl_->http.connection_cap(); }

int LiveServer::connections() const { return impl_->http.connections(); }

int LiveServer::sockets() const { return impl_->http.sockets(); }

struct LivePageClient::Impl {
  std::atomic<bool> done{false};
  std::atomic<int64_t> frames{0};
  std::thread frame_thread, stats_thread;
};

LivePageClient::LivePageClient(int port) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.frame_thread = std::thread([&m, port] {
    httplib::Client c("127.0.0.1", port);
    c.set_read_timeout(5, 0);
    int64_t after = -1;
    while (!m.done.load()) {
      auto r = c.Get(("/frame.png?after=" + std::to_string(after)).c_str());
      if (r && r->status == 200) {
        after = std::stoll(r->get_header_value("X-Frame"));
        m.frames.fetch_add(1, std::memory_order_relaxed);
      } else if (!r) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
    }
  });
  m.stats_thread = std::thread([&m, port] {
    httplib::Client c("127.0.0.1", port);
    int64_t next = 0;
    while (!m.done.load()) {
      if (auto r = c.Get(("/stats.json?since=" + std::to_string(next)).c_str()); r && r->status == 200) {
        const auto j = nlohmann::json::parse(r->body, nullptr, false);
        if (!j.is_discarded()) next = j.value("next", next);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
  });
}

LivePageClient::~LivePageClient() {
  impl_->done.store(true);
  impl_->frame_thread.join();
  impl_->stats_thread.join();
}

int64_t LivePageClient::frames() const { return impl_->frames.load(std::memory_order_relaxed); }

int64_t LiveServer::frames_sent() const { return impl_->frames_sent.load(std::memory_order_relaxed); }
int64_t LiveServer::frames_encoded() const { return impl_->frames_encoded.load(std::memory_order_relaxed); }

}  // namespace palpate
