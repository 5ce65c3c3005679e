#pragma once
/// Real-time set-up of the servo thread: memory locking, SCHED_FIFO, CPU pinning, timer slack.
/// Each request that the system refuses falls back cleanly and is reported, never fatal.

#include <string>

namespace palpate {

/// What to ask for.
struct RtRequest {
  bool lock_memory = true;   ///< mlockall(MCL_CURRENT | MCL_FUTURE), process-wide
  int fifo_priority = 80;    ///< SCHED_FIFO priority 1..99; 0 = stay with normal scheduling
  int cpu = -1;              ///< CPU to pin the servo to; -1 = the last CPU this process may use
};

/// What was granted.
struct RtGrant {
  bool memory_locked = false;  ///< mlockall succeeded
  bool fifo = false;           ///< SCHED_FIFO granted
  int priority = 0;            ///< its priority
  int cpu = -1;                ///< CPU pinned to, -1 when pinning failed
  bool timer_slack_1ns = false;///< PR_SET_TIMERSLACK 1 ns (the fallback for normal scheduling)
  std::string refused;         ///< one line naming what was refused and why; empty when all granted
};

/// Locks the process's memory (call once, from the controlling thread, before starting the servo).
bool lock_process_memory(std::string* why_not);

/// Applies priority, pinning and timer slack to the calling thread. Thread: the servo, before its loop
/// (not on the real-time path: it may fail, it does not log).
RtGrant apply_rt_to_this_thread(const RtRequest& request);

}  // namespace palpate
