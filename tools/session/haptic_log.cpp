#include "tools/session/haptic_log.h"

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace palpate {

HapticLog::~HapticLog() {
  if (f_) std::fclose(f_);
}

Status HapticLog::open(const std::string& path) {
  path_ = path;
  f_ = std::fopen((path + ".partial").c_str(), "w");
  if (!f_) return make_error("log '", path, "': ", std::strerror(errno));
  std::fputs("tick,t_s,tool_x_m,tool_y_m,tool_z_m,proxy_x_m,proxy_y_m,proxy_z_m,force_x_N,force_y_N,force_z_N,contact,buttons,rejected\n",
             f_);
  return Ok{};
}

void HapticLog::append(const HapticSample& s) {
  if (!f_ || !error_.empty()) return;
  const int n = std::fprintf(f_, "%lld,%.6f,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%u,%d\n",
                             static_cast<long long>(s.tick), s.t_s, s.tool_pos_m.x(), s.tool_pos_m.y(), s.tool_pos_m.z(),
                             s.proxy_pos_m.x(), s.proxy_pos_m.y(), s.proxy_pos_m.z(), s.force_N.x(), s.force_N.y(),
                             s.force_N.z(), static_cast<int>(s.contact), s.buttons, static_cast<int>(s.input_rejected));
  if (n < 0) error_ = std::strerror(errno);
  else ++rows_;
}

Status HapticLog::close() {
  if (!f_) return error_.empty() ? Status(Ok{}) : Status(make_error("log '", path_, "': ", error_));
  if (std::fflush(f_) != 0 && error_.empty()) error_ = std::strerror(errno);
  if (std::fclose(f_) != 0 && error_.empty()) error_ = std::strerror(errno);
  f_ = nullptr;
  if (!error_.empty()) return make_error("log '", path_, "': ", error_, " (partial rows kept in ", path_, ".partial)");
  std::error_code ec;
  std::filesystem::rename(path_ + ".partial", path_, ec);
  if (ec) return make_error("log '", path_, "': ", ec.message());
  return Ok{};
}

}  // namespace palpate
