#pragma once
/// What the machine took from the servo: steal time from /proc/stat (the hypervisor running something else on the
/// virtual CPU) and the servo thread's context switches. Read on the controlling thread or on the servo thread
/// outside its loop, never inside it (file I/O, allocation).

#include <cstdint>
#include <string_view>

#include "core/result.h"

namespace palpate {

/// The steal column of /proc/stat, in the kernel's clock ticks (USER_HZ).
struct StealTicks {
  int64_t total = 0;  ///< the "cpu" line: summed over all CPUs
  int64_t cpu = -1;   ///< the "cpuN" line of the CPU asked for; -1 when not asked for or not listed
};

/// Parses /proc/stat text: the 8th value (steal) of the "cpu" line and of the "cpuN" line for `cpu` (-1 = none).
/// A missing "cpu" line or one with fewer than 8 values is an error naming the line (kernels before 2.6.11 had no
/// steal column).
Result<StealTicks> parse_proc_stat_steal(std::string_view text, int cpu);

/// Reads /proc/stat now and parses it as above.
Result<StealTicks> read_proc_stat_steal(int cpu);

/// Milliseconds in `ticks` clock ticks (sysconf(_SC_CLK_TCK), 100 per second on Linux: 10 ms resolution).
double clock_ticks_ms(int64_t ticks);

/// Context switches of the calling thread so far (getrusage RUSAGE_THREAD); both -1 when refused.
/// Thread: any, outside real-time loops (one system call, no allocation).
struct ThreadSwitches {
  int64_t voluntary = -1;    ///< the thread gave up the CPU (a sleep)
  int64_t involuntary = -1;  ///< the CPU was taken from it (preempted, or its time slice ran out)
};
ThreadSwitches this_thread_switches() noexcept;

}  // namespace palpate
