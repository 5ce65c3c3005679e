#pragma once
// A small blocking WebSocket client for the live-view tests: connects to 127.0.0.1, upgrades GET /ws, sends masked
// frames (whole, or any raw bytes) and reads the server's frames.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <string>

namespace palpate::test {

/// One frame from the server. Plain data.
struct WsReceived {
  int opcode = -1;      ///< -1: nothing arrived (closed or timed out)
  std::string payload;  ///< as sent (server frames are not masked)
};

/// The client. Not copyable.
class WsClient {
 public:
  WsClient() = default;
  WsClient(const WsClient&) = delete;
  WsClient& operator=(const WsClient&) = delete;
  ~WsClient() { close_socket(); }

  /// Connects and sends the upgrade request (extra_headers end with CRLF each; host: the Host header, empty for
  /// 127.0.0.1:port); returns the server's reply head.
  std::string open(int port, const std::string& path = "/ws", const std::string& extra_headers = "",
                   const std::string& host = "") {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_port = htons(static_cast<uint16_t>(port));
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) return {};
    send_raw("GET " + path + " HTTP/1.1\r\nHost: " + (host.empty() ? "127.0.0.1:" + std::to_string(port) : host) +
             "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
             "Sec-WebSocket-Version: 13\r\n" + extra_headers + "\r\n");
    std::string head;
    while (head.find("\r\n\r\n") == std::string::npos) {
      char c;
      if (!wait_readable(5000) || ::recv(fd_, &c, 1, 0) != 1) break;
      head += c;
    }
    return head;
  }

  /// Sends bytes as they are.
  bool send_raw(const std::string& bytes) {
    return ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(bytes.size());
  }

  /// A masked client frame (final) of `opcode` carrying `payload`.
  static std::string frame(int opcode, const std::string& payload) {
    std::string f;
    f += static_cast<char>(0x80 | opcode);
    const uint8_t mask[4] = {0x37, 0xFA, 0x21, 0x3D};
    if (payload.size() < 126) {
      f += static_cast<char>(0x80 | payload.size());
    } else {
      f += static_cast<char>(0x80 | 126);
      f += static_cast<char>(payload.size() >> 8);
      f += static_cast<char>(payload.size() & 0xFF);
    }
    for (uint8_t m : mask) f += static_cast<char>(m);
    for (std::size_t i = 0; i < payload.size(); ++i) f += static_cast<char>(payload[i] ^ mask[i & 3]);
    return f;
  }

  /// Sends a text frame.
  bool send_text(const std::string& text) { return send_raw(frame(1, text)); }

  /// The next frame, waiting at most timeout_ms.
  WsReceived read(int timeout_ms = 5000) {
    WsReceived r;
    uint8_t h[2];
    if (!read_exact(h, 2, timeout_ms)) return r;
    std::size_t len = h[1] & 0x7F;
    if (len == 126) {
      uint8_t e[2];
      if (!read_exact(e, 2, timeout_ms)) return r;
      len = (std::size_t{e[0]} << 8) | e[1];
    } else if (len == 127) {
      return r;
    }
    r.payload.resize(len);
    if (len > 0 && !read_exact(reinterpret_cast<uint8_t*>(r.payload.data()), len, timeout_ms)) return r;
    r.opcode = h[0] & 0x0F;
    return r;
  }

  /// The next frame of `opcode`, skipping others, waiting at most timeout_ms in all.
  WsReceived read_until(int opcode, int timeout_ms = 5000) {
    for (int i = 0; i < 10000; ++i) {
      WsReceived r = read(timeout_ms);
      if (r.opcode == opcode || r.opcode < 0) return r;
    }
    return {};
  }

  /// True when the server closed the connection (reads until end of stream, at most timeout_ms).
  bool closed_by_server(int timeout_ms = 5000) {
    char buf[512];
    while (wait_readable(timeout_ms)) {
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) return true;
    }
    return false;
  }

  /// Closes the TCP connection without a close frame (a tab killed).
  void close_socket() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  bool wait_readable(int timeout_ms) {
    pollfd p{fd_, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms) > 0;
  }
  bool read_exact(uint8_t* out, std::size_t n, int timeout_ms) {
    std::size_t got = 0;
    while (got < n) {
      if (!wait_readable(timeout_ms)) return false;
      const ssize_t k = ::recv(fd_, out + got, n - got, 0);
      if (k <= 0) return false;
      got += static_cast<std::size_t>(k);
    }
    return true;
  }
  int fd_ = -1;
};

}  // namespace palpate::test
