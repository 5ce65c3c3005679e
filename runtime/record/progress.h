#pragma once
/// Progress: a recording's one progress line on stderr, rewritten in place on a terminal and printed once a second
/// otherwise; its last line says where the run ended (the whole scene, or where a stop request or a failure ended it).

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>

namespace palpate {

class Progress {
 public:
  Progress(bool quiet, std::string name, double duration_s)
      : quiet_(quiet), tty_(isatty(STDERR_FILENO)), name_(std::move(name)), duration_s_(duration_s),
        start_(std::chrono::steady_clock::now()) {}
  void update(double t_s, int64_t frame, int64_t frames, bool force = false) {
    last_t_s_ = t_s;
    last_frame_ = frame;
    if (quiet_) return;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (!force && wall - last_ < (tty_ ? 0.1 : 1.0)) return;
    last_ = wall;
    std::fprintf(stderr, "%srecord %s: %6.2f / %.2f s scene, frame %lld / %lld, %.1f s wall%s", tty_ ? "\r" : "",
                 name_.c_str(), t_s, duration_s_, static_cast<long long>(frame), static_cast<long long>(frames), wall,
                 tty_ ? "   " : "\n");
    std::fflush(stderr);
  }
  /// The run's last line: the whole scene when it ran to its end, else where it stopped (a Ctrl-C does not claim
  /// the frames it never made).
  void done(bool whole, int64_t frames) {
    if (whole) update(duration_s_, frames, frames, true);
    else update(last_t_s_, last_frame_, frames, true);
    if (!quiet_ && tty_) std::fputc('\n', stderr);
  }

 private:
  bool quiet_, tty_;
  std::string name_;
  double duration_s_;
  std::chrono::steady_clock::time_point start_;
  double last_ = -1.0;
  double last_t_s_ = 0.0;
  int64_t last_frame_ = 0;
};

}  // namespace palpate
