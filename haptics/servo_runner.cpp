#include "haptics/servo_runner.h"

#include <cmath>

#include "core/clock.h"

namespace palpate {

ServoRunner::ServoRunner(Servo* servo, const ServoRunnerConfig& config)
    : servo_(servo), config_(config), period_ns_(static_cast<int64_t>(std::llround(1e9 / config.rate_hz))) {}

ServoRunner::~ServoRunner() { stop(); }

const RtGrant& ServoRunner::start(int64_t t0_ns) {
  t0_ns_ = t0_ns;
  stop_.store(false);
  ready_.store(false);
  thread_ = std::thread([this] {
    timing_.rt = apply_rt_to_this_thread(config_.rt);  // set-up, before the real-time loop
    ready_.store(true, std::memory_order_release);
    run();
  });
  while (!ready_.load(std::memory_order_acquire)) std::this_thread::yield();
  return timing_.rt;
}

void ServoRunner::join() {
  if (config_.max_ticks < 0) stop();
  if (thread_.joinable()) thread_.join();
}

void ServoRunner::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void ServoRunner::run() noexcept {
  const int64_t spin_ns = static_cast<int64_t>(config_.spin_us) * 1000;
  int64_t tick = 0;
  int64_t next_ns = t0_ns_;
  while (!stop_.load(std::memory_order_relaxed) && (config_.max_ticks < 0 || tick < config_.max_ticks)) {
    // sleep to the deadline (or to just before it, then spin the rest)
    sleep_until_ns(next_ns - spin_ns);
    int64_t woke_ns = monotonic_ns();
    while (woke_ns < next_ns) woke_ns = monotonic_ns();
    timing_.wake_latency.add(woke_ns - next_ns);
    servo_->set_wake_latency_ns(woke_ns - next_ns);
    servo_->tick(tick, static_cast<double>(tick) * static_cast<double>(period_ns_) * 1e-9);
    const int64_t done_ns = monotonic_ns();
    timing_.compute.add(done_ns - woke_ns);
    ticks_.store(tick + 1, std::memory_order_relaxed);
    // next deadline; periods already past are skipped whole and counted
    ++tick;
    next_ns += period_ns_;
    if (done_ns > next_ns) {
      const int64_t missed = (done_ns - next_ns) / period_ns_ + 1;
      if (timing_.overrun_ticks_recorded < ServoTiming::kOverrunTicks)
        timing_.first_overrun_ticks[static_cast<std::size_t>(timing_.overrun_ticks_recorded++)] = tick;
      timing_.overruns += missed;
      tick += missed;
      next_ns += missed * period_ns_;
    }
  }
}

}  // namespace palpate
