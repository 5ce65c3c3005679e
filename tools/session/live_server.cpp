#include "tools/session/live_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <thread>

#include <httplib.h>
#include <png.h>
#include <zlib.h>

#include <nlohmann/json.hpp>

#include "core/clock.h"

namespace palpate {
namespace {

// a client that stops reading holds a server thread this long at most
constexpr int kWriteTimeout_s = 2;
// an idle kept-alive connection is closed after this long
constexpr int kKeepAlive_s = 2;
// how long /frame.png waits for a frame newer than the one the client has
constexpr int64_t kLongPoll_ns = 1'000'000'000;
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

// The server's threads run at nice 10: when the cores are short, the recording's threads (nice 0, the servo
// real-time) go first and the view gets fewer frames. Per thread (Linux nice values are per thread).
void lower_priority_once() {
  thread_local bool lowered = false;
  if (lowered) return;
  lowered = true;
  ::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 10);
}

int64_t int_param(const httplib::Request& req, const char* key, int64_t fallback) {
  if (!req.has_param(key)) return fallback;
  const std::string v = req.get_param_value(key);
  char* end = nullptr;
  errno = 0;
  const long long x = std::strtoll(v.c_str(), &end, 10);
  if (errno != 0 || end == v.c_str() || *end != '\0') return fallback;
  return x;
}

}  // namespace

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
  explicit Impl(LiveFeed* f) : feed(f) {}

  LiveFeed* feed;
  httplib::Server svr;
  std::thread listen_thread, collect_thread;
  std::atomic<bool> stopping{false};
  std::mutex stop_mutex;
  std::condition_variable stop_cv;
  bool started = false;
  std::string host;
  int port = 0;

  // the feed's reading side, one reader at a time
  std::mutex read_mutex;
  // plot points taken from the feed: points [history_begin, history_begin + history.size())
  std::mutex history_mutex;
  std::deque<LivePoint> history;
  int64_t history_begin = 0;
  std::vector<LivePoint> scratch;
  LiveFigures figures;

  // the newest frame as PNG, shared by every client asking for it
  std::mutex encode_mutex;
  std::vector<uint8_t> rgba;
  int64_t png_index = -1;
  std::shared_ptr<const std::string> png;

  std::atomic<int64_t> frames_sent{0}, frames_encoded{0};

  // takes the feed's new points and figures (collector thread and every /stats.json)
  void collect() {
    std::lock_guard<std::mutex> lr(read_mutex);
    scratch.clear();
    feed->take_points(&scratch);
    const LiveFigures f = feed->figures();
    std::lock_guard<std::mutex> lh(history_mutex);
    figures = f;
    for (const LivePoint& p : scratch) history.push_back(p);
    while (history.size() > kHistoryPoints) {
      history.pop_front();
      ++history_begin;
    }
  }

  // the newest frame encoded, when newer than `after` (nullptr otherwise)
  std::shared_ptr<const std::string> newest_png(int64_t after, int64_t* index) {
    std::lock_guard<std::mutex> le(encode_mutex);
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

  void frame(const httplib::Request& req, httplib::Response& res) {
    lower_priority_once();
    const int64_t after = int_param(req, "after", -1);
    const int64_t deadline = monotonic_ns() + kLongPoll_ns;
    int64_t index = -1;
    for (;;) {
      feed->want_frames_until(monotonic_ns() + kWantFrames_ns);
      if (auto p = newest_png(after, &index)) {
        res.set_header("Cache-Control", "no-store");
        res.set_header("X-Frame", std::to_string(index));
        res.set_content(*p, "image/png");
        frames_sent.fetch_add(1, std::memory_order_relaxed);
        return;
      }
      if (stopping.load() || monotonic_ns() > deadline) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    // nothing newer: the client asks again
    res.status = 204;
    res.set_header("Cache-Control", "no-store");
    res.set_header("X-Frame", std::to_string(index));
  }

  void stats(const httplib::Request& req, httplib::Response& res) {
    lower_priority_once();
    collect();
    int64_t since = int_param(req, "since", 0);
    nlohmann::json j;
    {
      std::lock_guard<std::mutex> lh(history_mutex);
      const LiveFigures& f = figures;
      j["scene"] = feed->scene();
      j["mode"] = feed->mode();
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
    }
    res.set_header("Cache-Control", "no-store");
    res.set_content(j.dump(), "application/json");
  }

  void collect_loop() {
    lower_priority_once();
    std::unique_lock<std::mutex> lock(stop_mutex);
    while (!stopping.load()) {
      lock.unlock();
      collect();
      lock.lock();
      stop_cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return stopping.load(); });
    }
  }
};

LiveServer::LiveServer(LiveFeed* feed) : impl_(std::make_unique<Impl>(feed)) {}

LiveServer::~LiveServer() { stop(); }

Status LiveServer::start(const ServeAddress& address) {
  Impl& m = *impl_;
  const std::string where = address.host + ":" + std::to_string(address.port);
  // a plain bind first: httplib says only that binding failed, the system says why
  {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return make_error("--serve ", where, ": cannot open a socket: ", std::strerror(errno));
    const int yes = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_port = htons(static_cast<uint16_t>(address.port));
    inet_pton(AF_INET, address.host.c_str(), &sa.sin_addr);
    const int rc = ::bind(fd, reinterpret_cast<const sockaddr*>(&sa), sizeof sa);
    const int err = errno;
    ::close(fd);
    if (rc != 0) return make_error("--serve ", where, ": cannot listen there: ", std::strerror(err));
  }
  m.svr.set_write_timeout(kWriteTimeout_s, 0);
  m.svr.set_read_timeout(kWriteTimeout_s, 0);
  m.svr.set_keep_alive_timeout(kKeepAlive_s);
  m.svr.set_tcp_nodelay(true);
  m.svr.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(live_page_html(), "text/html; charset=utf-8");
  });
  m.svr.Get("/frame.png", [&m](const httplib::Request& req, httplib::Response& res) { m.frame(req, res); });
  m.svr.Get("/stats.json", [&m](const httplib::Request& req, httplib::Response& res) { m.stats(req, res); });
  const int port = address.port == 0 ? m.svr.bind_to_any_port(address.host) : m.svr.bind_to_port(address.host, address.port) ? address.port : -1;
  if (port < 0) return make_error("--serve ", where, ": cannot listen there");
  m.host = address.host;
  m.port = port;
  m.listen_thread = std::thread([&m] { m.svr.listen_after_bind(); });
  // stop() must find the server running, or listen_after_bind would start after it and never end
  while (!m.svr.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  m.collect_thread = std::thread([&m] { m.collect_loop(); });
  m.started = true;
  return Ok{};
}

std::string LiveServer::url() const {
  const std::string host = impl_->host == "0.0.0.0" ? "127.0.0.1" : impl_->host;
  return "http://" + host + ":" + std::to_string(impl_->port) + "/";
}

int LiveServer::port() const { return impl_->port; }

void LiveServer::stop() {
  Impl& m = *impl_;
  if (!m.started) return;
  m.started = false;
  {
    std::lock_guard<std::mutex> lock(m.stop_mutex);
    m.stopping.store(true);
  }
  m.stop_cv.notify_all();
  m.svr.stop();
  if (m.listen_thread.joinable()) m.listen_thread.join();
  if (m.collect_thread.joinable()) m.collect_thread.join();
}

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
