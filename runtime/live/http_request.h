#pragma once
/// The head of one HTTP/1.x request, parsed with fixed limits: request line, header count and total size bounded,
/// GET and HEAD only, no body accepted. Pure functions, no I/O (fuzzed by tests/fuzz/http_head_fuzz.cpp).

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace palpate {

/// The limits a request head must keep. Plain data.
struct HttpHeadLimits {
  std::size_t max_line_bytes = 2048;  ///< request line ("GET /path?query HTTP/1.1"), without its CRLF
  std::size_t max_head_bytes = 8192;  ///< request line, headers and the blank line that ends them
  int max_headers = 32;               ///< header lines
};

/// A parsed request head. Plain data.
struct HttpRequest {
  std::string method;       ///< "GET" or "HEAD"
  std::string path;         ///< target before '?', e.g. "/frame.png"
  std::string query;        ///< target after '?', e.g. "after=12" (empty when none)
  bool keep_alive = false;  ///< HTTP/1.1 without "Connection: close", or HTTP/1.0 with "keep-alive"
  bool upgrade_websocket = false;  ///< "Connection: upgrade" and "Upgrade: websocket" (RFC 6455 §4.1)
  std::string ws_key;       ///< Sec-WebSocket-Key (empty when absent)
  std::string ws_version;   ///< Sec-WebSocket-Version (empty when absent)
  std::string host;         ///< Host (empty when absent)
  std::string origin;       ///< Origin (empty when absent: not a browser)
};

/// What parsing a head gave: a request (status 0) or the status to refuse it with (400, 405, 413, 414, 431, 505).
struct HttpHeadParse {
  int status = 0;       ///< 0 = request parsed
  HttpRequest request;  ///< valid when status == 0
  std::string reason;   ///< why it was refused, for the reply body
};

/// Where the head in `buffer` ends (one past its blank line): 0 while it is incomplete and still within the limits,
/// or a refusal status (negative: -414 request line too long, -431 head too large).
int64_t http_head_end(std::string_view buffer, const HttpHeadLimits& limits);

/// Parses a complete head (as delimited by http_head_end). A body (Content-Length above 0 or any
/// Transfer-Encoding) is refused with 413: nothing this server serves takes one.
HttpHeadParse parse_http_head(std::string_view head, const HttpHeadLimits& limits);

/// The integer value of `key` in a query string ("after=12&x=1"), or fallback when absent or not an integer.
int64_t query_int(std::string_view query, std::string_view key, int64_t fallback);

/// The reason phrase of a status code ("OK", "Request Header Fields Too Large", ...).
const char* http_reason(int status);

}  // namespace palpate
