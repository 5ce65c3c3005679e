#include "runtime/live/http_request.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>

namespace palpate {
namespace {

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// a comma-separated header value holds `token` (Connection: keep-alive, Upgrade)
bool has_token(std::string_view value, std::string_view token) {
  while (!value.empty()) {
    const auto comma = value.find(',');
    if (iequals(trim(value.substr(0, comma)), token)) return true;
    if (comma == std::string_view::npos) break;
    value.remove_prefix(comma + 1);
  }
  return false;
}

HttpHeadParse refuse(int status, std::string reason) {
  HttpHeadParse p;
  p.status = status;
  p.reason = std::move(reason);
  return p;
}

}  // namespace

int64_t http_head_end(std::string_view buffer, const HttpHeadLimits& limits) {
  const auto line_end = buffer.find("\r\n");
  const std::size_t line = line_end == std::string_view::npos ? buffer.size() : line_end;
  if (line > limits.max_line_bytes) return -414;
  const auto end = buffer.find("\r\n\r\n");
  if (end == std::string_view::npos) return buffer.size() >= limits.max_head_bytes ? -431 : 0;
  if (end + 4 > limits.max_head_bytes) return -431;
  return static_cast<int64_t>(end + 4);
}

HttpHeadParse parse_http_head(std::string_view head, const HttpHeadLimits& limits) {
  if (head.size() > limits.max_head_bytes) return refuse(431, "request head over " + std::to_string(limits.max_head_bytes) + " bytes");
  auto eol = head.find("\r\n");
  if (eol == std::string_view::npos) return refuse(400, "no request line");
  const std::string_view line = head.substr(0, eol);
  if (line.size() > limits.max_line_bytes)
    return refuse(414, "request line over " + std::to_string(limits.max_line_bytes) + " bytes");
  const auto sp1 = line.find(' ');
  const auto sp2 = sp1 == std::string_view::npos ? sp1 : line.find(' ', sp1 + 1);
  if (sp2 == std::string_view::npos || line.find(' ', sp2 + 1) != std::string_view::npos)
    return refuse(400, "request line is not METHOD TARGET VERSION");
  const std::string_view method = line.substr(0, sp1), target = line.substr(sp1 + 1, sp2 - sp1 - 1),
                         version = line.substr(sp2 + 1);
  if (version != "HTTP/1.1" && version != "HTTP/1.0") return refuse(505, "only HTTP/1.0 and HTTP/1.1 are served");
  if (target.empty() || target.front() != '/') return refuse(400, "the target is not a path");
  HttpHeadParse p;
  p.request.keep_alive = version == "HTTP/1.1";
  int headers = 0;
  bool upgrade_asked = false, websocket_asked = false;
  for (std::string_view rest = head.substr(eol + 2); !rest.empty();) {
    eol = rest.find("\r\n");
    if (eol == std::string_view::npos) return refuse(400, "a header line without CRLF");
    const std::string_view h = rest.substr(0, eol);
    rest.remove_prefix(eol + 2);
    if (h.empty()) break;  // the blank line
    if (++headers > limits.max_headers) return refuse(431, "more than " + std::to_string(limits.max_headers) + " header lines");
    const auto colon = h.find(':');
    if (colon == std::string_view::npos || colon == 0) return refuse(400, "a header line without a name");
    const std::string_view name = h.substr(0, colon), value = trim(h.substr(colon + 1));
    if (iequals(name, "Content-Length")) {
      if (value.empty() || value.find_first_not_of("0123456789") != std::string_view::npos)
        return refuse(400, "Content-Length is not a number");
      if (value.find_first_not_of('0') != std::string_view::npos) return refuse(413, "no request body is accepted");
    } else if (iequals(name, "Transfer-Encoding")) {
      return refuse(413, "no request body is accepted");
    } else if (iequals(name, "Connection")) {
      if (has_token(value, "close")) p.request.keep_alive = false;
      if (has_token(value, "keep-alive")) p.request.keep_alive = true;
      if (has_token(value, "upgrade")) upgrade_asked = true;
    } else if (iequals(name, "Upgrade")) {
      if (has_token(value, "websocket")) websocket_asked = true;
    } else if (iequals(name, "Sec-WebSocket-Key")) {
      p.request.ws_key = std::string(value);
    } else if (iequals(name, "Sec-WebSocket-Version")) {
      p.request.ws_version = std::string(value);
    } else if (iequals(name, "Host")) {
      p.request.host = std::string(value);
    } else if (iequals(name, "Origin")) {
      p.request.origin = std::string(value);
    }
  }
  if (method != "GET" && method != "HEAD") return refuse(405, "only GET and HEAD are served");
  p.request.method = std::string(method);
  p.request.upgrade_websocket = upgrade_asked && websocket_asked && method == "GET";
  const auto q = target.find('?');
  p.request.path = std::string(target.substr(0, q));
  if (q != std::string_view::npos) p.request.query = std::string(target.substr(q + 1));
  return p;
}

int64_t query_int(std::string_view query, std::string_view key, int64_t fallback) {
  while (!query.empty()) {
    const auto amp = query.find('&');
    const std::string_view kv = query.substr(0, amp);
    const auto eq = kv.find('=');
    if (eq != std::string_view::npos && kv.substr(0, eq) == key) {
      const std::string v(kv.substr(eq + 1));
      char* end = nullptr;
      errno = 0;
      const long long x = std::strtoll(v.c_str(), &end, 10);
      if (errno != 0 || end == v.c_str() || *end != '\0') return fallback;
      return x;
    }
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return fallback;
}

const char* http_reason(int status) {
  switch (status) {
    case 101: return "Switching Protocols";
    case 200: return "OK";
    case 204: return "No Content";
    case 400: return "Bad Request";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 408: return "Request Timeout";
    case 413: return "Content Too Large";
    case 414: return "URI Too Long";
    case 426: return "Upgrade Required";
    case 431: return "Request Header Fields Too Large";
    case 503: return "Service Unavailable";
    case 505: return "HTTP Version Not Supported";
    default: return "Error";
  }
}

}  // namespace palpate
