// The live view's server: addresses it refuses before anything is recorded, and clients that stop reading while a
// realtime recording runs (they must cost the recording nothing).
#include <gtest/gtest.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <memory>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "support/cli_run.h"
#include "support/fixtures.h"
#include "tools/session/live_feed.h"
#include "tools/session/live_server.h"
#include "tools/session/recorder.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

// a TCP socket listening on 127.0.0.1 at a port the system picked; closed with the object
struct BusyPort {
  int fd = -1;
  int port = 0;
  BusyPort() {
    fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) == 0 && ::listen(fd, 4) == 0) {
      socklen_t len = sizeof sa;
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&sa), &len);
      port = ntohs(sa.sin_port);
    }
  }
  ~BusyPort() { ::close(fd); }
};

// a client that asks for frames and never reads the answers: a tiny receive buffer, many requests queued on it
int stalled_client(int port, int requests) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  const int small = 1024;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(static_cast<uint16_t>(port));
  sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
    ::close(fd);
    return -1;
  }
  std::string req;
  for (int i = 0; i < requests; ++i) req += "GET /frame.png?after=-1 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
  if (::send(fd, req.data(), req.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(req.size())) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// one GET answered in full (Connection: close); the raw response
std::string http_get(int port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  const timeval limit{30, 0};  // a server that never answers fails the test instead of hanging it
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
  sockaddr_in sa{};
  sa.sin_family = AF_INET;
  sa.sin_port = htons(static_cast<uint16_t>(port));
  sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  std::string out;
  if (::connect(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) == 0) {
    const std::string req = "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
    if (::send(fd, req.data(), req.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(req.size())) {
      char buf[65536];
      for (ssize_t n; (n = ::recv(fd, buf, sizeof buf, 0)) > 0;) out.append(buf, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  return out;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in, nullptr, false);
}

TEST(LiveServe, AddressesParseOrNameWhatIsWrong) {
  auto a = parse_serve_address("8080");
  ASSERT_TRUE(a);
  EXPECT_EQ(a.value().host, "127.0.0.1");
  EXPECT_EQ(a.value().port, 8080);
  a = parse_serve_address("0.0.0.0:0");
  ASSERT_TRUE(a);
  EXPECT_EQ(a.value().host, "0.0.0.0");
  EXPECT_EQ(a.value().port, 0);
  EXPECT_EQ(parse_serve_address("localhost:9").value().host, "127.0.0.1");
  for (const char* bad : {"", "http", "80a", "70000", "host:80", "1.2.3:80", ":80", "127.0.0.1:", "-1"}) {
    const auto r = parse_serve_address(bad);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().message.find(std::string("'") + bad + "'"), std::string::npos) << r.error().message;
  }
}

TEST(LiveServe, PortInUseFailsBeforeAnythingIsRecorded) {
  BusyPort busy;
  ASSERT_GT(busy.port, 0);
  const std::string out = test::fresh_dir("live_busy");
  const std::string where = "127.0.0.1:" + std::to_string(busy.port);
  const auto r = test::palpate("record scenes/cube_press.json --mode realtime --serve " + where + " --out " + out);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("palpate: --serve " + where + ": cannot listen there: Address already in use"), std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(out)) << "an output folder was left behind";
}

TEST(LiveServe, BadAddressFailsBeforeAnythingIsRecorded) {
  const std::string out = test::fresh_dir("live_bad_address");
  for (const std::string bad : {"nowhere:8080", "127.0.0.1:65536", "203.0.113.9:8080"}) {
    const auto r = test::palpate("record scenes/cube_press.json --serve " + bad + " --out " + out);
    EXPECT_EQ(r.code, 2) << bad << ": " << r.out;
    EXPECT_NE(r.out.find("palpate: --serve"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(bad), std::string::npos) << r.out;
    EXPECT_FALSE(fs::exists(out)) << bad << ": an output folder was left behind";
  }
  const auto r = test::palpate("record scenes/cube_press.json --serve-linger 5 --out " + out);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("palpate: --serve-linger needs --serve"), std::string::npos) << r.out;
}

// More stalled clients than the server has threads, each with frames queued it never reads, during a realtime
// recording: every frame is still written, none is dropped for the view's sake, and the summary is the usual one.
TEST(LiveServe, ClientsThatStopReadingCostTheRecordingNothing) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  LiveFeed feed(scene.render.width, scene.render.height, "cube_press", "realtime");
  feed.keep_frames();
  LiveServer server(&feed);
  ASSERT_TRUE(server.start(ServeAddress{"127.0.0.1", 0}));
  // the first frames exist before the clients stall (so each request has a whole PNG to send)
  RecordOptions opt;
  opt.out_dir = test::fresh_dir("live_stalled");
  opt.override_mode = true;
  opt.mode = RunMode::kRealtime;
  opt.duration_s = 3.0;
  opt.quiet = true;
  opt.live = &feed;
  std::vector<int> stalled;
  std::unique_ptr<LivePageClient> viewer;
  std::thread clients([&] {
    while (feed.frame_index() < 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    for (int i = 0; i < 12; ++i) stalled.push_back(stalled_client(server.port(), 40));
    // and one viewer that reads, as the page does: it waits for a server thread like everybody else
    viewer = std::make_unique<LivePageClient>(server.port());
  });
  auto r = record_scene(scene, opt);
  clients.join();
  viewer.reset();
  ASSERT_TRUE(r) << r.error().message;
  for (int fd : stalled) EXPECT_GE(fd, 0) << "a client could not connect";
  const auto s = read_json(r.value().summary_path);
  const int64_t frames = 180;
  // every frame rendered and written: the stalled clients held the server's threads, never the sim thread
  EXPECT_EQ(s["frames_written"].get<int64_t>() + s["sim"]["frames_late"].get<int64_t>(), frames) << s.dump();
  EXPECT_EQ(s["frames_dropped"].get<int64_t>(), 0);
  EXPECT_LT(s["sim"]["frames_late"].get<int64_t>(), frames / 10) << "the sim thread stalled";
  EXPECT_EQ(s["png"]["write_errors"].get<int64_t>(), 0);
  EXPECT_EQ(s["nan_events"].get<int64_t>(), 0);
  EXPECT_EQ(s["dropped_samples"].get<int64_t>(), 0);
  EXPECT_GT(s["max_force_N"].get<double>(), 0.5);
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(opt.out_dir) / "frames")) files += e.path().extension() == ".png";
  EXPECT_EQ(files, s["frames_written"].get<int64_t>());
  // the server is still answering other clients: the final figures are those of the summary
  const std::string stats = http_get(server.port(), "/stats.json");
  const auto body = stats.find("\r\n\r\n");
  ASSERT_NE(body, std::string::npos) << stats;
  const auto j = nlohmann::json::parse(stats.substr(body + 4), nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << stats;
  EXPECT_TRUE(j["finished"].get<bool>());
  EXPECT_EQ(j["frames_written"], s["frames_written"]);
  EXPECT_EQ(j["servo"]["ticks"], s["servo_ticks"]);
  for (int fd : stalled) ::close(fd);
  server.stop();
}

}  // namespace
}  // namespace palpate
