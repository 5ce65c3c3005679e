// libFuzzer target: the bytes a live-view client sends -> http_head_end() and parse_http_head(), as the server
// feeds them (the buffer grows up to the head limit). Whatever arrives: a head end within the buffer and the
// limit, a refusal status among those the server sends, and a parsed request only for GET or HEAD with a path.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "runtime/live/http_request.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  using namespace palpate;
  const HttpHeadLimits limits;
  const std::string_view in(reinterpret_cast<const char*>(data), size);
  // the server holds at most max_head_bytes of a head
  const std::string_view buffer = in.substr(0, limits.max_head_bytes);
  const int64_t end = http_head_end(buffer, limits);
  if (end < 0 && end != -414 && end != -431) std::abort();
  if (end > static_cast<int64_t>(buffer.size()) || end > static_cast<int64_t>(limits.max_head_bytes)) std::abort();
  if (end > 0) {
    const HttpHeadParse p = parse_http_head(buffer.substr(0, static_cast<std::size_t>(end)), limits);
    switch (p.status) {
      case 0:
        if (p.request.method != "GET" && p.request.method != "HEAD") std::abort();
        if (p.request.path.empty() || p.request.path.front() != '/') std::abort();
        (void)query_int(p.request.query, "after", -1);
        break;
      case 400: case 405: case 413: case 414: case 431: case 505:
        if (p.reason.empty()) std::abort();
        break;
      default:
        std::abort();
    }
  }
  return 0;
}
