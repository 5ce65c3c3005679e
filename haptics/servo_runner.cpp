#include "haptics/servo_runner.h"

#include <pthread.h>
#include <sched.h>

#include <cmath>

#include "core/clock.h"

namespace palpate {

ServoRunner::ServoRunner(Servo* servo, double rate_hz, int fifo_priority)
    : servo_(servo), period_ns_(static_cast<int64_t>(std::llround(1e9 / rate_hz))), fifo_priority_(fifo_priority) {}

ServoRunner::~ServoRunner() { stop(); }

void ServoRunner::start(int64_t t0_ns) {
  t0_ns_ = t0_ns;
  stop_.store(false);
  thread_ = std::thread([this] { run(); });
  if (fifo_priority_ > 0) {
    // before the first deadline (t0 is set a little ahead by callers); refused without privileges
    sched_param sp{};
    sp.sched_priority = fifo_priority_;
    if (pthread_setschedparam(thread_.native_handle(), SCHED_FIFO, &sp) == 0) {
      timing_.realtime_priority = true;
      timing_.priority = fifo_priority_;
    }
  }
}

void ServoRunner::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void ServoRunner::run() noexcept {
  int64_t tick = 0;
  int64_t next_ns = t0_ns_;
  while (!stop_.load(std::memory_order_relaxed)) {
    sleep_until_ns(next_ns);
    const int64_t woke_ns = monotonic_ns();
    timing_.wake_latency.add(woke_ns - next_ns);
    servo_->tick(tick, static_cast<double>(tick) * static_cast<double>(period_ns_) * 1e-9);
    const int64_t done_ns = monotonic_ns();
    timing_.compute.add(done_ns - woke_ns);
    ticks_.store(tick + 1, std::memory_order_relaxed);
    // next deadline; periods already past are skipped whole and counted
    ++tick;
    next_ns += period_ns_;
    if (done_ns > next_ns) {
      const int64_t missed = (done_ns - next_ns) / period_ns_ + 1;
      timing_.overruns += missed;
      tick += missed;
      next_ns += missed * period_ns_;
    }
  }
}

}  // namespace palpate
