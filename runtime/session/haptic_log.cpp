#include "runtime/session/haptic_log.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>

namespace palpate {
namespace {

// The rows of a kept log: its lines (each ends in a newline) less the header; -1 when it cannot be opened.
int64_t count_rows(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return -1;
  int64_t lines = 0;
  char block[65536];
  for (ssize_t n; (n = ::read(fd, block, sizeof block)) != 0;) {
    if (n < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (ssize_t i = 0; i < n; ++i) lines += block[i] == '\n';
  }
  ::close(fd);
  return lines > 0 ? lines - 1 : 0;
}

}  // namespace

void haptic_log_values(const HapticSample& s, double out[kHapticLogWidth]) {
  const double v[kHapticLogWidth] = {static_cast<double>(s.tick), s.t_s, s.tool_pos_m.x(), s.tool_pos_m.y(),
                                     s.tool_pos_m.z(), s.proxy_pos_m.x(), s.proxy_pos_m.y(), s.proxy_pos_m.z(),
                                     s.force_N.x(), s.force_N.y(), s.force_N.z(), static_cast<double>(s.contact),
                                     static_cast<double>(s.buttons), static_cast<double>(s.input_rejected),
                                     static_cast<double>(s.drain_frame), static_cast<double>(s.model_frame),
                                     s.force_scale, static_cast<double>(s.controls.seq),
                                     static_cast<double>(s.controls.mode), s.controls.stiffness_scale,
                                     s.controls.tool_radius_m, static_cast<double>(s.controls.resets)};
  for (int i = 0; i < kHapticLogWidth; ++i) out[i] = v[i];
}

Status HapticLog::open(const std::string& path) {
  auto f = AtomicFile::open(path, "log", ".partial");
  if (!f) return f.error();
  file_ = std::move(f).value();
  file_.write(std::string(kHapticLogColumns) + "\n");
  return Ok{};
}

void HapticLog::append(const HapticSample& s) {
  if (keep_) keep_->push_back(s);
  if (!file_.good()) return;
  // the controls' values in the shortest text that reads back to the same double (a replay starts the model again
  // under exactly these)
  char stiffness[32], radius[32];
  *std::to_chars(stiffness, stiffness + sizeof stiffness - 1, s.controls.stiffness_scale).ptr = '\0';
  *std::to_chars(radius, radius + sizeof radius - 1, s.controls.tool_radius_m).ptr = '\0';
  const int n = std::fprintf(file_.stream(),
                             "%lld,%.6f,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d,%u,%d,%lld,%lld,%.17g,%lld,%d,%s,"
                             "%s,%lld\n",
                             static_cast<long long>(s.tick), s.t_s, s.tool_pos_m.x(), s.tool_pos_m.y(), s.tool_pos_m.z(),
                             s.proxy_pos_m.x(), s.proxy_pos_m.y(), s.proxy_pos_m.z(), s.force_N.x(), s.force_N.y(),
                             s.force_N.z(), static_cast<int>(s.contact), s.buttons, static_cast<int>(s.input_rejected),
                             static_cast<long long>(s.drain_frame), static_cast<long long>(s.model_frame), s.force_scale,
                             static_cast<long long>(s.controls.seq), static_cast<int>(s.controls.mode),
                             stiffness, radius, static_cast<long long>(s.controls.resets));
  if (n < 0) file_.fail(std::strerror(errno));
  else ++rows_;
}

Status HapticLog::close() {
  if (file_.path().empty()) return Ok{};  // never opened
  // partial rows stay in "<path>.partial" when a write failed (e.g. disk full)
  Status st = file_.commit(/*keep_partial=*/true);
  if (st) {
    // every row reached the disk (flush, fsync and rename succeeded)
    kept_path_ = file_.path();
    kept_rows_ = rows_;
    return st;
  }
  // the rows the stream accepted are not the rows on disk: count what the .partial holds, if it is there
  const int64_t kept = count_rows(file_.temp_path());
  kept_path_ = kept >= 0 ? file_.temp_path() : std::string();
  kept_rows_ = kept >= 0 ? kept : 0;
  return st;
}

}  // namespace palpate
