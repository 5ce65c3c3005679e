// The live view against hostile clients (loopback only, every loop bounded in count and time): request heads,
// bodies, slow senders, many connections and a descriptor limit. The server answers each with a bounded refusal
// and the recording beside it is the same, frame for frame and state for state, as without a view.
#include <gtest/gtest.h>
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/clock.h"
#include "core/scene.h"
#include "support/fixtures.h"
#include "support/http_get.h"
#include "support/read_file.h"
#include "runtime/live/http_server.h"
#include "runtime/live/live_feed.h"
#include "runtime/live/live_server.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

// a blocking loopback connection with 5 s send and receive timeouts; -1 when refused
int connect_to(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const timeval limit{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &limit, sizeof limit);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(static_cast<uint16_t>(port));
  sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

bool readable(int fd, int timeout_ms) {
  pollfd p{fd, POLLIN, 0};
  return ::poll(&p, 1, timeout_ms) > 0;
}

// what the server answered (up to 64 KiB, until it closes or 5 s pass)
std::string reply(int fd) {
  std::string out;
  char buf[4096];
  while (out.size() < 65536 && readable(fd, 5000)) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
  }
  return out;
}

// Sends `head`, then `chunk` again and again until the server answers, refuses more, or `most` bytes went out;
// returns the bytes sent and the answer.
std::pair<std::size_t, std::string> flood(int port, const std::string& head, const std::string& chunk, std::size_t most) {
  const int fd = connect_to(port);
  if (fd < 0) return {0, "(no connection)"};
  std::size_t sent = 0;
  if (::send(fd, head.data(), head.size(), MSG_NOSIGNAL) > 0) sent += head.size();
  while (sent < most && !readable(fd, 0)) {
    const ssize_t n = ::send(fd, chunk.data(), chunk.size(), MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<std::size_t>(n);
  }
  std::string r = reply(fd);
  ::close(fd);
  return {sent, r};
}

// a kept-alive reply's head (until the blank line)
std::string reply_head(int fd) {
  std::string out;
  char buf[4096];
  while (out.find("\r\n\r\n") == std::string::npos && out.size() < 65536 && readable(fd, 5000)) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
  }
  return out;
}

std::string status_line(const std::string& r) { return r.substr(0, r.find("\r\n")); }

// Every part of a request a client controls has a bound, and a request past it gets its refusal at once,
// having cost the server a few KiB: endless header lines (the old server read them until the process died),
// too many headers, an endless request line, a body (none is accepted, whatever its size), another method.
TEST(LiveAbuse, RequestHeadsAndBodiesAreBounded) {
  LiveFeed feed(64, 48, "abuse", "lockstep");
  LiveServer server(&feed);
  ASSERT_TRUE(server.start(ServeAddress{"127.0.0.1", 0}));
  const int port = server.port();
  const std::string line4k = "X-Fill: " + std::string(4086, 'a') + "\r\n";
  auto [sent, r] = flood(port, "GET / HTTP/1.1\r\nHost: x\r\n", line4k, std::size_t{64} << 20);
  EXPECT_EQ(status_line(r), "HTTP/1.1 431 Request Header Fields Too Large") << r.substr(0, 200);
  // what was sent before the answer arrived: the server's 8 KiB plus the loopback socket buffers (a few MiB
  // here), far below the 64 MiB the client would send to a server that kept reading
  EXPECT_LT(sent, std::size_t{16} << 20) << "the server read on past its head limit";

  std::string many = "GET / HTTP/1.1\r\n";
  for (int i = 0; i < 40; ++i) many += "X-" + std::to_string(i) + ": 1\r\n";
  std::tie(sent, r) = flood(port, many + "\r\n", "", 0);
  EXPECT_EQ(status_line(r), "HTTP/1.1 431 Request Header Fields Too Large") << r;
  EXPECT_NE(r.find("more than 32 header lines"), std::string::npos) << r;

  std::tie(sent, r) = flood(port, "GET /", std::string(4096, 'a'), std::size_t{64} << 20);
  EXPECT_EQ(status_line(r), "HTTP/1.1 414 URI Too Long") << r.substr(0, 200);
  EXPECT_LT(sent, std::size_t{16} << 20);

  // a 1 GiB body announced: refused from the head, the body never read (the client's sends fail early)
  std::tie(sent, r) = flood(port, "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 1073741824\r\n\r\n",
                            std::string(65536, 'b'), std::size_t{1} << 30);
  EXPECT_EQ(status_line(r), "HTTP/1.1 413 Content Too Large") << r.substr(0, 200);
  EXPECT_LT(sent, std::size_t{64} << 20);
  std::tie(sent, r) = flood(port, "DELETE / HTTP/1.1\r\nHost: x\r\n\r\n", "", 0);
  EXPECT_EQ(status_line(r), "HTTP/1.1 405 Method Not Allowed") << r;
  EXPECT_NE(r.find("Allow: GET, HEAD"), std::string::npos) << r;
  std::tie(sent, r) = flood(port, "GET / HTTP/1.1\r\nHost: x\r\nContent-Length: 1073741824\r\n\r\n",
                            std::string(65536, 'b'), std::size_t{1} << 30);
  EXPECT_EQ(status_line(r), "HTTP/1.1 413 Content Too Large") << r.substr(0, 200);
  EXPECT_LT(sent, std::size_t{64} << 20);
  std::tie(sent, r) = flood(port, "GET / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n", "", 0);
  EXPECT_EQ(status_line(r), "HTTP/1.1 413 Content Too Large") << r;
  std::tie(sent, r) = flood(port, "GET /nothing HTTP/1.1\r\nConnection: close\r\n\r\n", "", 0);
  EXPECT_EQ(status_line(r), "HTTP/1.1 404 Not Found") << r;

  // and it still serves the page
  const std::string page = test::http_get(port, "/");
  EXPECT_EQ(status_line(page), "HTTP/1.1 200 OK") << page.substr(0, 200);
  EXPECT_NE(page.find("<html"), std::string::npos);
  server.stop();
}

// Ten clients sending a header byte at a time (the old server gave each a thread, and had eight) leave the
// server answering at once, are closed at the request deadline, and do not hold up stop().
TEST(LiveAbuse, SlowSendersHoldNeitherTheServerNorItsStop) {
  std::atomic<int> answered{0};
  HttpLimits limits;
  limits.head_timeout_ms = 600;
  HttpServer server(
      [&](const HttpRequest&, bool) {
        ++answered;
        HttpReply r;
        r.content_type = "text/plain";
        r.body = std::make_shared<const std::string>("ok\n");
        return r;
      },
      nullptr, 100, limits);
  ASSERT_TRUE(server.start("127.0.0.1", 0));
  std::vector<int> slow;
  for (int i = 0; i < 10; ++i) {
    slow.push_back(connect_to(server.port()));
    ASSERT_GE(slow.back(), 0);
    ASSERT_GT(::send(slow.back(), "GET / HTTP/1.1\r\n", 16, MSG_NOSIGNAL), 0);
  }
  // one byte each every 50 ms: never a whole head; a normal request meanwhile gets its answer
  std::atomic<bool> done{false};
  std::thread dribble([&] {
    for (int round = 0; round < 100 && !done.load(); ++round) {
      for (int fd : slow) ::send(fd, "X", 1, MSG_NOSIGNAL | MSG_DONTWAIT);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
  const std::string r = test::http_get(server.port(), "/");
  EXPECT_EQ(status_line(r), "HTTP/1.1 200 OK") << r;
  EXPECT_EQ(answered.load(), 1);
  // each slow client is closed at the head deadline, however steadily it sends
  for (int fd : slow) {
    char buf[256];
    ssize_t n = 1;
    for (int i = 0; i < 50 && n > 0; ++i)
      if (readable(fd, 200)) n = ::recv(fd, buf, sizeof buf, 0);
    EXPECT_LE(n, 0) << "a slow client is still connected";
  }
  EXPECT_GE(server.timed_out(), 10);
  done.store(true);
  dribble.join();
  for (int fd : slow) ::close(fd);
  // a client that never reads its reply and one mid-head: stop() returns all the same (a bound far past the
  // 0.5 s grace, so a loaded machine passes and a stop that waits on clients fails)
  const int stalled = connect_to(server.port());
  const int half = connect_to(server.port());
  ASSERT_GT(::send(half, "GET", 3, MSG_NOSIGNAL), 0);
  ASSERT_GT(::send(stalled, "GET / HTTP/1.1\r\n\r\n", 18, MSG_NOSIGNAL), 0);
  auto stopped = std::async(std::launch::async, [&] { server.stop(); });
  EXPECT_EQ(stopped.wait_for(std::chrono::seconds(20)), std::future_status::ready) << "stop() waits on a client";
  stopped.wait();
  EXPECT_EQ(server.connections(), 0);
  ::close(stalled);
  ::close(half);
}

// The port of a run a browser watched is free for the next run at once: the server closes connections first
// (so its side waits in TIME_WAIT), and binds with SO_REUSEADDR.
TEST(LiveAbuse, PortIsFreeAgainRightAfterAWatchedRun) {
  LiveFeed feed(64, 48, "abuse", "lockstep");
  int port = 0;
  {
    LiveServer first(&feed);
    ASSERT_TRUE(first.start(ServeAddress{"127.0.0.1", 0}));
    port = first.port();
    for (int i = 0; i < 3; ++i) EXPECT_EQ(status_line(test::http_get(port, "/stats.json")), "HTTP/1.1 200 OK");
    const int kept = connect_to(port);  // a browser's kept-alive connection, open when the run ends
    ASSERT_GT(::send(kept, "GET / HTTP/1.1\r\n\r\n", 18, MSG_NOSIGNAL), 0);
    EXPECT_EQ(status_line(reply_head(kept)), "HTTP/1.1 200 OK");
    first.stop();
    ::close(kept);
  }
  LiveServer second(&feed);
  const Status st = second.start(ServeAddress{"127.0.0.1", port});
  EXPECT_TRUE(st) << st.error().message;
  EXPECT_EQ(status_line(test::http_get(port, "/stats.json")), "HTTP/1.1 200 OK");
}


nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in, nullptr, false);
}

int png_files(const std::string& out) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(fs::path(out) / "frames")) n += e.path().extension() == ".png";
  return n;
}

void expect_same_recording(const nlohmann::json& a, const nlohmann::json& s) {
  ASSERT_FALSE(a.is_discarded());
  ASSERT_FALSE(s.is_discarded()) << "no summary.json";
  EXPECT_EQ(s["state_hash"], a["state_hash"]);
  for (const char* key : {"frames_written", "frames_dropped", "servo_ticks", "haptic_rows", "max_force_N",
                          "max_displacement_m", "nan_events", "dropped_samples"})
    EXPECT_EQ(s[key], a[key]) << key;
}

// Every kind of abuse at once, for the whole of a lockstep recording: header floods, slow senders, bodies,
// connections opened and dropped. The recording is the one made without a view: every frame, the same state.
TEST(LiveAbuse, RecordingIsWholeWhateverClientsDo) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  RecordOptions opt;
  opt.out_dir = test::fresh_dir("abuse_plain");
  opt.override_mode = true;
  opt.mode = RunMode::kLockstep;
  opt.duration_s = 2.0;
  opt.quiet = true;
  auto plain = record_scene(scene, opt);
  ASSERT_TRUE(plain) << plain.error().message;

  LiveFeed feed(scene.render.width, scene.render.height, "cube_press", "lockstep");
  LiveServer server(&feed);
  ASSERT_TRUE(server.start(ServeAddress{"127.0.0.1", 0}));
  const int port = server.port();
  std::atomic<bool> done{false};
  std::vector<std::thread> clients;
  const std::string line4k = "X-Fill: " + std::string(4086, 'a') + "\r\n";
  // at most 200 rounds (about 20 s) each, ended early when the recording is over
  for (int k = 0; k < 4; ++k)
    clients.emplace_back([&] {
      for (int i = 0; i < 200 && !done.load(); ++i) flood(port, "GET / HTTP/1.1\r\n", line4k, std::size_t{4} << 20);
    });
  clients.emplace_back([&] {
    for (int i = 0; i < 200 && !done.load(); ++i)
      flood(port, "POST / HTTP/1.1\r\nContent-Length: 1073741824\r\n\r\n", std::string(65536, 'b'), std::size_t{16} << 20);
  });
  clients.emplace_back([&] {
    for (int i = 0; i < 200 && !done.load(); ++i) {
      std::vector<int> fds;
      for (int c = 0; c < 100; ++c) {
        const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
        sockaddr_in sa{};
        sa.sin_family = AF_INET;
        sa.sin_port = htons(static_cast<uint16_t>(port));
        sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        ::connect(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa);
        ::send(fd, "GET /frame.png?after=-1 HTTP/1.1\r\n", 34, MSG_NOSIGNAL);  // never finished
        fds.push_back(fd);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      for (int fd : fds) ::close(fd);
    }
  });
  clients.emplace_back([&] {
    std::vector<int> slow;
    for (int c = 0; c < 10; ++c) slow.push_back(connect_to(port));
    for (int i = 0; i < 400 && !done.load(); ++i) {
      for (int fd : slow) ::send(fd, "G", 1, MSG_NOSIGNAL | MSG_DONTWAIT);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    for (int fd : slow) ::close(fd);
  });
  // and one well-behaved page, which must keep getting frames
  auto page = std::make_unique<LivePageClient>(port);
  opt.out_dir = test::fresh_dir("abuse_live");
  opt.live = &feed;
  auto r = record_scene(scene, opt);
  const int64_t page_frames = page->frames();
  page.reset();
  done.store(true);
  for (auto& t : clients) t.join();
  ASSERT_TRUE(r) << r.error().message;
  expect_same_recording(read_json(plain.value().summary_path), read_json(r.value().summary_path));
  EXPECT_EQ(png_files(opt.out_dir), png_files(plain.value().summary_path.substr(0, plain.value().summary_path.rfind('/'))));
  EXPECT_GT(page_frames, 0) << "the page got no frame while the abuse went on";
  EXPECT_EQ(status_line(test::http_get(port, "/stats.json")), "HTTP/1.1 200 OK");
  server.stop();
}

// `palpate record --serve` under a 96-descriptor limit with 200 connections held open against it: the server
// takes at most what the limit leaves after the recording's reserve, so every frame file is written and the
// recording is the one made without a view.
TEST(LiveAbuse, ConnectionsLeaveTheRecordingItsDescriptors) {
  const char* bin_env = std::getenv("PALPATE_BIN_DIR");
  const std::string bin = std::string(bin_env ? bin_env : "build/bin") + "/palpate";
  const std::string scene = test::source_path("scenes/cube_press.json");
  const std::string plain = test::fresh_dir("fd_plain"), live = test::fresh_dir("fd_live");
  ASSERT_EQ(std::system((bin + " record " + scene + " --mode lockstep --no-video --duration 3 --out " + plain +
                         " > /dev/null 2>&1").c_str()), 0);
  const std::string log = live + ".log";
  fs::remove(log);
  ASSERT_EQ(std::system(("(ulimit -n 96; " + bin + " record " + scene +
                         " --mode lockstep --no-video --duration 3 --serve 127.0.0.1:0 --out " + live +
                         "; echo \"exit $?\") > " + log + " 2>&1 &").c_str()), 0);
  // the port from "live view at http://127.0.0.1:PORT/", then 200 connections kept open (re-opened when
  // closed) until the run ends; at most 120 s
  int port = 0;
  std::string text;
  std::vector<int> fds;
  const int64_t end_ns = monotonic_ns() + int64_t{120'000'000'000};
  for (; monotonic_ns() < end_ns; std::this_thread::sleep_for(std::chrono::milliseconds(5))) {
    text = test::read_file(log);
    if (text.find("exit ") != std::string::npos) break;
    std::smatch m;
    if (port == 0 && std::regex_search(text, m, std::regex("live view at http://127\\.0\\.0\\.1:([0-9]+)/")))
      port = std::stoi(m[1]);
    if (port == 0) continue;
    for (auto& fd : fds) {
      char b;
      if (::recv(fd, &b, 1, MSG_DONTWAIT | MSG_PEEK) == 0) {
        ::close(fd);
        fd = -1;
      }
    }
    std::erase(fds, -1);
    while (fds.size() < 200) {
      const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
      sockaddr_in sa{};
      sa.sin_family = AF_INET;
      sa.sin_port = htons(static_cast<uint16_t>(port));
      sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      ::connect(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa);
      fds.push_back(fd);
    }
  }
  for (int fd : fds) ::close(fd);
  ASSERT_NE(port, 0) << text;
  ASSERT_NE(text.find("exit 0"), std::string::npos) << text;
  EXPECT_EQ(text.find("Too many open files"), std::string::npos) << text;
  expect_same_recording(read_json(plain + "/summary.json"), read_json(live + "/summary.json"));
  EXPECT_EQ(png_files(live), 180);
}

}  // namespace
}  // namespace palpate
