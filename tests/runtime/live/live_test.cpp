// The live view's server: addresses it refuses before anything is recorded, and clients that stop reading while a
// realtime recording runs (they must cost the recording nothing).
#include <gtest/gtest.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <future>
#include <memory>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "support/cli_run.h"
#include "support/http_get.h"
#include "support/fixtures.h"
#include "runtime/live/live_feed.h"
#include "runtime/live/live_server.h"
#include "runtime/record/recorder.h"

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
  // an empty address is no "no live view": it is refused, not run without the view the user asked for
  const auto empty = test::palpate("record scenes/cube_press.json --serve '' --out " + out);
  EXPECT_EQ(empty.code, 2) << empty.out;
  EXPECT_NE(empty.out.find("palpate: --serve '': give [ADDR:]PORT"), std::string::npos) << empty.out;
  EXPECT_FALSE(fs::exists(out)) << "an output folder was left behind";
  const auto r = test::palpate("record scenes/cube_press.json --serve-linger 5 --out " + out);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("palpate: --serve-linger needs --serve"), std::string::npos) << r.out;
}

// More stalled clients than the server has threads, each with frame requests queued behind a receive buffer it
// never reads, before and during a recording: the recording is the one it is without a view (every frame, the
// same state), and the server still answers afterwards. Lockstep, so "every frame" and "the same" are exact on a
// loaded machine; a sim thread that waited for the view would wait here for threads the stalled clients hold.
TEST(LiveServe, ClientsThatStopReadingCostTheRecordingNothing) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  RecordOptions opt;
  opt.out_dir = test::fresh_dir("live_plain");
  opt.override_mode = true;
  opt.mode = RunMode::kLockstep;
  opt.duration_s = 3.0;
  opt.quiet = true;
  auto plain = record_scene(scene, opt);
  ASSERT_TRUE(plain) << plain.error().message;

  LiveFeed feed(scene.render.width, scene.render.height, "cube_press", "lockstep");
  feed.keep_frames();
  LiveServer server(&feed);
  ASSERT_TRUE(server.start(ServeAddress{"127.0.0.1", 0}));
  // a noisy frame (a PNG far larger than the socket buffers) for the clients' requests before the recording
  std::vector<uint8_t> noise(static_cast<std::size_t>(scene.render.width * scene.render.height * 4));
  uint32_t x = 12345;
  for (auto& b : noise) b = static_cast<uint8_t>((x = x * 1664525u + 1013904223u) >> 24);
  feed.offer_frame(0, noise.data());
  std::vector<int> stalled;
  for (int i = 0; i < 12; ++i) stalled.push_back(stalled_client(server.port(), 40));
  for (int fd : stalled) ASSERT_GE(fd, 0) << "a client could not connect";
  // every server thread is then stuck writing a PNG nobody reads (until its 2 s write timeout, then the next client)
  for (int i = 0; i < 6000 && server.frames_sent() < 8; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_GE(server.frames_sent(), 8) << "the clients were not stalled on frames";
  opt.out_dir = test::fresh_dir("live_stalled");
  opt.live = &feed;
  // a recording that waited for the stalled clients would not end: a bound far past the second this one takes
  auto done = std::async(std::launch::async, [&] { return record_scene(scene, opt); });
  if (done.wait_for(std::chrono::seconds(120)) != std::future_status::ready) {
    std::fprintf(stderr, "the recording did not end in 120 s: the sim thread waits for the live view\n");
    std::fflush(stderr);
    std::_Exit(1);  // the recording's thread cannot be joined
  }
  auto r = done.get();
  ASSERT_TRUE(r) << r.error().message;
  const auto a = read_json(plain.value().summary_path);
  const auto s = read_json(r.value().summary_path);
  EXPECT_EQ(s["frames_written"].get<int64_t>(), 180);
  EXPECT_EQ(s["state_hash"], a["state_hash"]);
  for (const char* key : {"frames_written", "frames_dropped", "servo_ticks", "haptic_rows", "max_force_N",
                          "max_displacement_m", "nan_events", "dropped_samples"})
    EXPECT_EQ(s[key], a[key]) << key;
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(opt.out_dir) / "frames")) files += e.path().extension() == ".png";
  EXPECT_EQ(files, 180);
  // the server still answers: the final figures are those of the summary
  const std::string stats = test::http_get(server.port(), "/stats.json");
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
