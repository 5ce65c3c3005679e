#include "haptics/servo/rt_setup.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>

#include <cerrno>
#include <cstring>

namespace palpate {

bool lock_process_memory(std::string* why_not) {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) return true;
  if (why_not) *why_not = std::string("mlockall: ") + std::strerror(errno);
  return false;
}

RtGrant apply_rt_to_this_thread(const RtRequest& request) {
  RtGrant g;
  auto refuse = [&](const std::string& what) { g.refused += (g.refused.empty() ? "" : "; ") + what; };

  // pin: the requested CPU, or the last one the process may run on (the others keep GL and PNG work)
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) == 0) {
    int cpu = request.cpu;
    if (cpu < 0)
      for (int c = CPU_SETSIZE - 1; c >= 0; --c)
        if (CPU_ISSET(c, &allowed)) {
          cpu = c;
          break;
        }
    cpu_set_t one;
    CPU_ZERO(&one);
    if (cpu >= 0 && cpu < CPU_SETSIZE) CPU_SET(cpu, &one);
    const int rc = cpu >= 0 ? pthread_setaffinity_np(pthread_self(), sizeof one, &one) : EINVAL;
    if (rc == 0) g.cpu = cpu;
    else refuse("pin to CPU " + std::to_string(cpu) + ": " + std::strerror(rc));
  }

  if (request.fifo_priority > 0) {
    sched_param sp{};
    sp.sched_priority = request.fifo_priority;
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
    if (rc == 0) {
      g.fifo = true;
      g.priority = request.fifo_priority;
    } else {
      refuse("SCHED_FIFO " + std::to_string(request.fifo_priority) + ": " + std::strerror(rc));
    }
  }
  // without real-time priority, at least stop the kernel from coalescing our wake-ups
  if (!g.fifo) g.timer_slack_1ns = prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL) == 0;
  return g;
}

}  // namespace palpate
