// palpate-shim-bench: round-trip latency pose -> force through the shared-memory shim between two processes.
// A child process plays the device: every period it publishes a pose, then spins until the force answering it
// arrives. The parent plays the servo side: it spins on the pose record and answers each new pose at once.
// Prints median, p99, p99.9 and max of the round trip (us), measured on the device side's clock.

#include <sched.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "core/clock.h"
#include "haptics/devices/shm_segment.h"

namespace {

using palpate::monotonic_ns;

// Pins the calling process to one CPU and asks for SCHED_FIFO (falls back to normal scheduling).
void pin(int cpu) {
  sched_param sp{};
  sp.sched_priority = 60;
  sched_setscheduler(0, SCHED_FIFO, &sp);
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  sched_setaffinity(0, sizeof set, &set);
}

// Device side: n round trips at period_ns; returns the latencies (ns).
std::vector<int64_t> device_side(palpate_shim_segment* s, int n, int64_t period_ns) {
  std::vector<int64_t> rtt;
  rtt.reserve(static_cast<std::size_t>(n));
  int64_t next = monotonic_ns() + 10'000'000;
  for (uint64_t seq = 1; static_cast<int>(rtt.size()) < n; ++seq) {
    palpate::sleep_until_ns(next);
    next += period_ns;
    palpate_shim_pose p{};
    p.seq = seq;
    p.time_ns = monotonic_ns();
    p.quat_wxyz[0] = 1.0;
    palpate_shim_write_pose(&s->pose, &p);
    palpate_shim_beat(&s->device_hb, p.time_ns);
    const int64_t give_up = p.time_ns + 100'000'000;
    palpate_shim_force f{};
    while (monotonic_ns() < give_up)
      if (palpate_shim_read_force(&s->force, &f, 1) && f.pose_seq == seq) {
        rtt.push_back(monotonic_ns() - p.time_ns);
        break;
      }
  }
  return rtt;
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 5000;
  const std::string name = "bench-" + std::to_string(getpid());
  palpate_shim_specs specs{3.3, 700, 0.5, 1000, {}};
  auto seg = palpate::ShmSegment::serve(name, specs);
  if (!seg) {
    std::fprintf(stderr, "palpate-shim-bench: %s\n", seg.error().message.c_str());
    return 1;
  }
  palpate_shim_segment* s = seg.value().get();
  const pid_t child = fork();
  if (child == 0) {
    // the servo side: answer every new pose at once
    pin(0);
    uint64_t last = 0, fseq = 0;
    const int64_t end = monotonic_ns() + 60'000'000'000LL;
    while (monotonic_ns() < end && __atomic_load_n(&s->header.device_state, __ATOMIC_ACQUIRE) != PALPATE_SHIM_DEVICE_STOPPED) {
      palpate_shim_pose p{};
      if (!palpate_shim_read_pose(&s->pose, &p, 1) || p.seq == last) continue;
      last = p.seq;
      palpate_shim_force f{};
      f.seq = ++fseq;
      f.time_ns = monotonic_ns();
      f.pose_seq = p.seq;
      f.pose_time_ns = p.time_ns;
      palpate_shim_write_force(&s->force, &f);
      palpate_shim_beat(&s->sim_hb, f.time_ns);
    }
    _exit(0);
  }
  pin(1);
  std::vector<int64_t> rtt = device_side(s, n, 1'000'000);
  __atomic_store_n(&s->header.device_state, uint64_t{PALPATE_SHIM_DEVICE_STOPPED}, __ATOMIC_RELEASE);
  waitpid(child, nullptr, 0);
  palpate::ShmSegment::unlink(name);
  std::sort(rtt.begin(), rtt.end());
  auto q = [&](double f) { return static_cast<double>(rtt[std::min(rtt.size() - 1, static_cast<std::size_t>(f * static_cast<double>(rtt.size())))]) / 1e3; };
  std::printf("shim round trip pose -> force, 2 processes on 2 CPUs (SCHED_FIFO %s), 1 kHz, %zu samples: median %.2f us, p99 %.2f us, "
              "p99.9 %.2f us, max %.2f us\n",
              sched_getscheduler(0) == SCHED_FIFO ? "granted" : "refused", rtt.size(), q(0.5), q(0.99), q(0.999), static_cast<double>(rtt.back()) / 1e3);
  return 0;
}
