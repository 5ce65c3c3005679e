#include "tools/session/haptic_log.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace palpate {

Status HapticLog::open(const std::string& path) {
  auto f = AtomicFile::open(path, "log", ".partial");
  if (!f) return f.error();
  file_ = std::move(f).value();
  file_.write("tick,t_s,tool_x_m,tool_y_m,tool_z_m,proxy_x_m,proxy_y_m,proxy_z_m,force_x_N,force_y_N,force_z_N,contact,buttons,rejected\n");
  return Ok{};
}

void HapticLog::append(const HapticSample& s) {
  if (!file_.good()) return;
  const int n = std::fprintf(file_.stream(), "%lld,%.6f,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%u,%d\n",
                             static_cast<long long>(s.tick), s.t_s, s.tool_pos_m.x(), s.tool_pos_m.y(), s.tool_pos_m.z(),
                             s.proxy_pos_m.x(), s.proxy_pos_m.y(), s.proxy_pos_m.z(), s.force_N.x(), s.force_N.y(),
                             s.force_N.z(), static_cast<int>(s.contact), s.buttons, static_cast<int>(s.input_rejected));
  if (n < 0) file_.fail(std::strerror(errno));
  else ++rows_;
}

Status HapticLog::close() {
  if (file_.path().empty()) return Ok{};  // never opened
  // partial rows stay in "<path>.partial" when a write failed (e.g. disk full)
  return file_.commit(/*keep_partial=*/true);
}

}  // namespace palpate
