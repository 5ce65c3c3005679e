#pragma once
/// Monotonic clock helpers (CLOCK_MONOTONIC, nanoseconds); safe on the servo thread.

#include <cerrno>
#include <cstdint>
#include <ctime>

namespace palpate {

/// Now on CLOCK_MONOTONIC in nanoseconds.
inline int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1'000'000'000LL + ts.tv_nsec;
}

/// Sleeps until the absolute CLOCK_MONOTONIC time t_ns (retries on EINTR).
inline void sleep_until_ns(int64_t t_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / 1'000'000'000LL);
  ts.tv_nsec = static_cast<long>(t_ns % 1'000'000'000LL);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace palpate
