// SHA-1 against FIPS 180 test vectors, base64 against RFC 4648's, the RFC 6455 handshake example, and the
// WebSocket frame parser's rules (masking, fragments, sizes, control frames, text).
#include <gtest/gtest.h>

#include <string>

#include "support/ws_client.h"
#include "runtime/live/browser_message.h"
#include "runtime/live/http_server.h"
#include "runtime/live/sha1.h"
#include "runtime/live/ws_frame.h"

namespace palpate {
namespace {

std::string hex(const std::array<uint8_t, 20>& d) {
  static const char* k = "0123456789abcdef";
  std::string s;
  for (uint8_t b : d) {
    s += k[b >> 4];
    s += k[b & 15];
  }
  return s;
}

TEST(Sha1, FipsVectors) {
  EXPECT_EQ(hex(sha1("abc")), "a9993e364706816aba3e25717850c26c9cd0d89d");
  EXPECT_EQ(hex(sha1("")), "da39a3ee5e6b4b0d3255bfef95601890afd80709");
  // 448 bits: the padding needs a second block
  EXPECT_EQ(hex(sha1("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq")),
            "84983e441c3bd26ebaae4aa1f95129e5e54670f1");
  EXPECT_EQ(hex(sha1(std::string(1000000, 'a'))), "34aa973cd4c4daa4f61eeb2bdbad27316534016f");
  // every tail length around the block boundary hashes (55, 56, 63, 64 bytes) without two equal digests
  EXPECT_NE(hex(sha1(std::string(55, 'x'))), hex(sha1(std::string(56, 'x'))));
  EXPECT_NE(hex(sha1(std::string(63, 'x'))), hex(sha1(std::string(64, 'x'))));
}

TEST(Base64, Rfc4648Vectors) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
}

TEST(WebSocketHandshake, Rfc6455Example) {
  EXPECT_EQ(websocket_accept("dGhlIHNhbXBsZSBub25jZQ=="), "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=");
}

HttpRequest upgrade_request() {
  HttpRequest r;
  r.method = "GET";
  r.path = "/ws";
  r.upgrade_websocket = true;
  r.ws_key = "dGhlIHNhbXBsZSBub25jZQ==";
  r.ws_version = "13";
  r.host = "127.0.0.1:8080";
  return r;
}

std::string header(const HttpReply& r, const std::string& name) {
  for (const auto& [k, v] : r.headers)
    if (k == name) return v;
  return {};
}

TEST(WebSocketHandshake, UpgradeRepliesAndRefusals) {
  HttpRequest req = upgrade_request();
  HttpReply ok = websocket_upgrade(req);
  EXPECT_EQ(ok.status, 101);
  EXPECT_TRUE(ok.upgrade);
  EXPECT_EQ(header(ok, "Sec-WebSocket-Accept"), "s3pPLMBiTxaQ9kYGzzhZRbK+xOo=");
  // the page's own origin is accepted; another site's is refused
  req.origin = "http://127.0.0.1:8080";
  EXPECT_EQ(websocket_upgrade(req).status, 101);
  req.origin = "http://evil.example";
  const HttpReply foreign = websocket_upgrade(req);
  EXPECT_EQ(foreign.status, 403);
  EXPECT_NE(foreign.body->find("Origin 'http://evil.example'"), std::string::npos) << *foreign.body;
  // through an SSH tunnel (ssh -L 9000:127.0.0.1:8080) the browser names the tunnel's end in both Host and Origin: the
  // page works there; another port or scheme is another site
  req.host = "localhost:9000";
  req.origin = "http://localhost:9000";
  EXPECT_EQ(websocket_upgrade(req).status, 101);
  for (const char* other : {"http://localhost:8080", "https://localhost:9000", "http://localhost", "null"}) {
    req.origin = other;
    EXPECT_EQ(websocket_upgrade(req).status, 403) << other;
  }
  req = upgrade_request();
  req.ws_version = "8";
  const HttpReply old = websocket_upgrade(req);
  EXPECT_EQ(old.status, 426);
  EXPECT_EQ(header(old, "Sec-WebSocket-Version"), "13");
  req = upgrade_request();
  req.ws_key = "short==";
  EXPECT_EQ(websocket_upgrade(req).status, 400);
  req = upgrade_request();
  req.upgrade_websocket = false;
  EXPECT_EQ(websocket_upgrade(req).status, 400);
}

// A server on loopback takes its socket only from a page whose Host names loopback: a page of another site whose
// name was pointed at 127.0.0.1 (DNS rebinding) sends its own name in both Host and Origin, which match.
TEST(WebSocketHandshake, ALoopbackServerRefusesAHostThatIsNotLoopback) {
  for (const char* host : {"127.0.0.1:8080", "localhost:9000", "LocalHost:9000", "localhost", "127.1.2.3:80", "[::1]:8080"})
    EXPECT_TRUE(loopback_host(host)) << host;
  for (const char* host : {"evil.example:8080", "127.0.0.1.evil.example:8080", "localhost.evil.example", "128.0.0.1:8080",
                           "127.0.0.256", "127.0.0", "127..0.1", "[::2]:8080", "[::1", "", "0.0.0.0:8080"})
    EXPECT_FALSE(loopback_host(host)) << host;
  HttpRequest req = upgrade_request();
  req.host = "evil.example:8080";
  req.origin = "http://evil.example:8080";
  EXPECT_EQ(websocket_upgrade(req).status, 101) << "a server on all interfaces is reached by any name";
  const HttpReply rebound = websocket_upgrade(req, true);
  EXPECT_EQ(rebound.status, 403);
  EXPECT_NE(rebound.body->find("Host 'evil.example:8080' is not a loopback name"), std::string::npos) << *rebound.body;
  req.host = "localhost:9000";  // an SSH tunnel's end
  req.origin = "http://localhost:9000";
  EXPECT_EQ(websocket_upgrade(req, true).status, 101);
}

TEST(HttpHead, UpgradeHeadersAreRead) {
  const std::string head =
      "GET /ws HTTP/1.1\r\nHost: h:1\r\nConnection: keep-alive, Upgrade\r\nUpgrade: websocket\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\nOrigin: http://h:1\r\n\r\n";
  const HttpHeadParse p = parse_http_head(head, HttpHeadLimits{});
  ASSERT_EQ(p.status, 0) << p.reason;
  EXPECT_TRUE(p.request.upgrade_websocket);
  EXPECT_EQ(p.request.ws_key, "dGhlIHNhbXBsZSBub25jZQ==");
  EXPECT_EQ(p.request.host, "h:1");
  EXPECT_EQ(websocket_upgrade(p.request).status, 101);
  // Upgrade without Connection: upgrade is no upgrade
  const HttpHeadParse q = parse_http_head("GET /ws HTTP/1.1\r\nUpgrade: websocket\r\n\r\n", HttpHeadLimits{});
  EXPECT_FALSE(q.request.upgrade_websocket);
}

WsParse parse(const std::string& bytes) { return ws_parse_frame(bytes, WsLimits{}); }

TEST(WsFrame, MaskedTextIsUnmasked) {
  const std::string f = test::WsClient::frame(1, "p 1 0.5 -0.5 0 0");
  const WsParse p = parse(f);
  ASSERT_EQ(p.kind, WsParse::Kind::kFrame) << p.reason;
  EXPECT_EQ(p.consumed, f.size());
  EXPECT_EQ(p.payload, "p 1 0.5 -0.5 0 0");
  // a frame followed by the start of the next takes only its own bytes; every prefix is incomplete
  EXPECT_EQ(parse(f + f.substr(0, 3)).consumed, f.size());
  for (std::size_t n = 0; n < f.size(); ++n) EXPECT_EQ(parse(f.substr(0, n)).kind, WsParse::Kind::kIncomplete) << n;
  // RFC 6455 §5.7's masked "Hello"
  const WsParse hello = parse(std::string("\x81\x85\x37\xfa\x21\x3d\x7f\x9f\x4d\x51\x58", 11));
  ASSERT_EQ(hello.kind, WsParse::Kind::kFrame);
  EXPECT_EQ(hello.payload, "Hello");
}

TEST(WsFrame, RuleBreakersAreRefusedWithTheirCode) {
  struct Case {
    std::string bytes;
    uint16_t code;
    const char* reason;
  };
  const std::string unmasked("\x81\x05Hello", 7);
  std::string rsv = test::WsClient::frame(1, "x");
  rsv[0] = static_cast<char>(rsv[0] | 0x40);
  std::string fragment = test::WsClient::frame(1, "x");
  fragment[0] = 0x01;
  const std::string big = test::WsClient::frame(1, std::string(257, 'a'));
  const std::string long_ping = std::string("\x89\xFE\x00\x7E", 4);
  const std::string not_shortest = std::string("\x81\xFE\x00\x05", 4);
  const std::string huge = std::string("\x82\xFF\x80\x00\x00\x00\x00\x00\x00\x00", 10);
  const std::string one_byte_close = test::WsClient::frame(8, "x");
  const std::string control_chars = test::WsClient::frame(1, "a\nb");
  const Case cases[] = {
      {unmasked, kWsCloseProtocol, "not masked"},
      {rsv, kWsCloseProtocol, "reserved bits"},
      {std::string("\x83\x80", 2), kWsCloseProtocol, "unknown opcode 3"},
      {fragment, kWsCloseUnsupported, "fragmented"},
      {big, kWsCloseTooBig, "257 bytes over the limit of 256"},
      {long_ping, kWsCloseProtocol, "control frame over 125"},
      {not_shortest, kWsCloseProtocol, "shortest form"},
      {huge, kWsCloseProtocol, "top bit"},
      {one_byte_close, kWsCloseProtocol, "one-byte payload"},
      {control_chars, kWsCloseBadData, "printable ASCII"},
  };
  for (const Case& c : cases) {
    const WsParse p = parse(c.bytes);
    ASSERT_EQ(p.kind, WsParse::Kind::kError) << c.reason;
    EXPECT_EQ(p.close_code, c.code) << c.reason;
    EXPECT_NE(p.reason.find(c.reason), std::string::npos) << p.reason;
  }
  // an oversize frame is refused from its header alone, before its payload arrives
  EXPECT_EQ(parse(big.substr(0, 4)).kind, WsParse::Kind::kError);
}

TEST(WsFrame, ServerFramesRoundTrip) {
  const std::string f = ws_encode_frame(WsOpcode::kText, std::string(300, 'z'));
  EXPECT_EQ(static_cast<uint8_t>(f[0]), 0x81);
  EXPECT_EQ(static_cast<uint8_t>(f[1]), 126);
  EXPECT_EQ(f.size(), 304u);
  const std::string c = ws_close_payload(1009, std::string(200, 'r'));
  EXPECT_EQ(c.size(), 125u);
  EXPECT_EQ(static_cast<uint8_t>(c[0]) * 256 + static_cast<uint8_t>(c[1]), 1009);
}

TEST(BrowserMessage, PoseAndLatencyParse) {
  const BrowserMessage p = parse_browser_message("p 12 0.25 -1 1 1");
  ASSERT_EQ(p.kind, BrowserMessage::Kind::kPose) << p.reason;
  EXPECT_EQ(p.seq, 12);
  EXPECT_EQ(p.x, 0.25);
  EXPECT_EQ(p.y, -1.0);
  EXPECT_EQ(p.depth, 1.0);
  EXPECT_EQ(p.buttons, 1u);
  const BrowserMessage l = parse_browser_message("l 14.5 -1");
  ASSERT_EQ(l.kind, BrowserMessage::Kind::kLatency) << l.reason;
  EXPECT_EQ(l.force_ms, 14.5);
  EXPECT_EQ(l.frame_ms, -1.0);
}

TEST(BrowserMessage, GarbageNamesTheField) {
  const std::pair<const char*, const char*> cases[] = {
      {"", "empty message"},
      {"p 1 0 0 0", "5 fields expected"},
      {"p 0 0 0 0 0", "SEQ '0' is not a positive integer"},
      {"p 1 1.5 0 0 0", "X '1.5' is not a number in -1..1"},
      {"p 1 0 nan 0 0", "Y 'nan' is not a number"},
      {"p 1 0 0 inf 0", "DEPTH 'inf'"},
      {"p 1 0 0 0 4", "BUTTONS '4' is not 0..3"},
      {"p 1 0 0 0 0 ", "5 fields expected"},
      {"l 1e9 0", "FORCE_MS '1e9'"},
      {"x", "unknown message 'x'"},
  };
  for (const auto& [text, reason] : cases) {
    const BrowserMessage m = parse_browser_message(text);
    EXPECT_EQ(m.kind, BrowserMessage::Kind::kError) << text;
    EXPECT_NE(m.reason.find(reason), std::string::npos) << text << " -> " << m.reason;
  }
}

}  // namespace
}  // namespace palpate
