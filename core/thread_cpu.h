#pragma once
/// The calling thread's CPU time: what a piece of work costs whatever else shares the machine.

#include <time.h>

namespace palpate {

/// CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID), ms.
inline double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

}  // namespace palpate
