// WebSockets on the live view's HTTP server, over real loopback sockets: the upgrade, messages both ways, ping and
// close, and the bounds: a frame breaking a rule closes the socket with its code, a socket cap, an idle deadline,
// and a page that vanishes is noticed.
#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "support/ws_client.h"
#include "runtime/live/http_server.h"

namespace palpate {
namespace {

// A server that upgrades /ws and echoes each message with "echo " in front; records the callbacks.
struct EchoServer {
  explicit EchoServer(HttpLimits limits = {})
      : http(
            [](const HttpRequest& r, bool) {
              if (r.path == "/ws") return websocket_upgrade(r);
              HttpReply none;
              none.status = 404;
              return none;
            },
            {}, 50, limits) {
    http.set_websocket({[this](int64_t id, const HttpRequest&) { note("open " + std::to_string(id)); },
                        [this](int64_t id, WsOpcode, std::string_view text) {
                          note("message " + std::string(text));
                          http.ws_send(id, "echo " + std::string(text));
                        },
                        [this](int64_t, const std::string& why) { note("close " + why); },
                        {}});
    EXPECT_TRUE(http.start("127.0.0.1", 0));
  }
  void note(const std::string& e) {
    std::lock_guard<std::mutex> l(m);
    events.push_back(e);
  }
  // waits up to 5 s for an event starting with `prefix`; returns it (empty when none came)
  std::string wait_for(const std::string& prefix) {
    for (int i = 0; i < 500; ++i) {
      {
        std::lock_guard<std::mutex> l(m);
        for (const auto& e : events)
          if (e.rfind(prefix, 0) == 0) return e;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return {};
  }
  HttpServer http;
  std::mutex m;
  std::vector<std::string> events;
};

TEST(WsServer, UpgradeEchoPingAndClose) {
  EchoServer s;
  test::WsClient c;
  const std::string head = c.open(s.http.port());
  EXPECT_EQ(head.rfind("HTTP/1.1 101 Switching Protocols\r\n", 0), 0u) << head;
  EXPECT_NE(head.find("Sec-WebSocket-Accept: s3pPLMBiTxaQ9kYGzzhZRbK+xOo=\r\n"), std::string::npos) << head;
  EXPECT_FALSE(s.wait_for("open").empty());
  EXPECT_EQ(s.http.sockets(), 1);
  ASSERT_TRUE(c.send_text("hello"));
  const auto r = c.read();
  EXPECT_EQ(r.opcode, 1);
  EXPECT_EQ(r.payload, "echo hello");
  ASSERT_TRUE(c.send_raw(test::WsClient::frame(9, "pp")));
  const auto pong = c.read();
  EXPECT_EQ(pong.opcode, 10);
  EXPECT_EQ(pong.payload, "pp");
  ASSERT_TRUE(c.send_raw(test::WsClient::frame(8, std::string("\x03\xE8", 2))));
  const auto bye = c.read();
  EXPECT_EQ(bye.opcode, 8);
  EXPECT_TRUE(c.closed_by_server());
  EXPECT_EQ(s.wait_for("close"), "close closed by the page");
}

TEST(WsServer, AFrameBreakingARuleClosesWithItsCode) {
  EchoServer s;
  test::WsClient c;
  c.open(s.http.port());
  ASSERT_TRUE(c.send_raw(std::string("\x81\x05Hello", 7)));  // not masked
  const auto r = c.read();
  ASSERT_EQ(r.opcode, 8);
  ASSERT_GE(r.payload.size(), 2u);
  EXPECT_EQ(static_cast<uint8_t>(r.payload[0]) * 256 + static_cast<uint8_t>(r.payload[1]), kWsCloseProtocol);
  EXPECT_NE(r.payload.find("not masked"), std::string::npos);
  EXPECT_TRUE(c.closed_by_server());
  EXPECT_EQ(s.wait_for("close"), "close client frame not masked");
  EXPECT_EQ(s.http.ws_refused(), 1);
  // a message over the limit: refused from its header, 1009
  test::WsClient d;
  d.open(s.http.port());
  ASSERT_TRUE(d.send_raw(test::WsClient::frame(1, std::string(1000, 'a'))));
  const auto big = d.read();
  ASSERT_EQ(big.opcode, 8);
  EXPECT_EQ(static_cast<uint8_t>(big.payload[0]) * 256 + static_cast<uint8_t>(big.payload[1]), kWsCloseTooBig);
}

TEST(WsServer, SocketCapIdleDeadlineAndAVanishedPage) {
  HttpLimits limits;
  limits.max_sockets = 2;
  limits.ws_idle_timeout_ms = 300;
  EchoServer s(limits);
  test::WsClient a, b, c;
  EXPECT_EQ(a.open(s.http.port()).rfind("HTTP/1.1 101", 0), 0u);
  EXPECT_EQ(b.open(s.http.port()).rfind("HTTP/1.1 101", 0), 0u);
  EXPECT_EQ(c.open(s.http.port()).rfind("HTTP/1.1 503", 0), 0u) << "a third socket over the cap of 2";
  // a page that vanishes without a close frame is noticed at once
  b.close_socket();
  EXPECT_EQ(s.wait_for("close"), "close page gone");
  // a silent page is closed after the idle deadline
  EXPECT_TRUE(a.closed_by_server(3000));
  for (int i = 0; i < 100 && s.http.sockets() > 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(s.http.sockets(), 0);
  EXPECT_GE(s.http.timed_out(), 1);
}

}  // namespace
}  // namespace palpate
