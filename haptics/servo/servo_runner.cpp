#include "haptics/servo/servo_runner.h"

#include <cmath>

#include "core/clock.h"
#include "haptics/servo/cpu_steal.h"

namespace palpate {

SpinWindow::SpinWindow(int64_t period_ns, int64_t initial_ns) noexcept
    : cap_ns_(max_spin_window_ns(period_ns)),
      window_ns_(initial_ns < 0 ? 0 : (initial_ns < cap_ns_ ? initial_ns : cap_ns_)) {}

void SpinWindow::add(int64_t sleep_late_ns) noexcept {
  int64_t b = sleep_late_ns < 0 ? 0 : sleep_late_ns / 1000;
  if (b >= kBuckets) b = kBuckets - 1;
  auto& slot = ring_[static_cast<std::size_t>(added_ % kSamples)];
  if (added_ >= kSamples) --counts_[slot];  // the oldest sample leaves
  slot = static_cast<uint16_t>(b);
  ++counts_[static_cast<std::size_t>(b)];
  ++added_;
  if (added_ >= kMinSamples && added_ % kUpdateEvery == 0) update();
}

void SpinWindow::update() noexcept {
  const int64_t n = added_ < kSamples ? added_ : kSamples;
  const auto need = static_cast<int64_t>(std::ceil(kQuantile * static_cast<double>(n)));
  int64_t seen = 0;
  int b = 0;
  for (; b < kBuckets - 1; ++b) {
    seen += counts_[static_cast<std::size_t>(b)];
    if (seen >= need) break;
  }
  const int64_t want = (b + 1) * 1000 + kMarginNs;  // the bucket's upper edge, plus the margin
  window_ns_ = want < cap_ns_ ? want : cap_ns_;
}

ServoRunner::ServoRunner(Servo* servo, const Rates& rates, const ServoRunnerConfig& config)
    : servo_(servo), rates_(rates), config_(config) {}

ServoRunner::~ServoRunner() { stop(); }

const RtGrant& ServoRunner::start(int64_t t0_ns) {
  t0_ns_ = t0_ns;
  stop_.store(false);
  ready_.store(false);
  finished_.store(false);
  thread_ = std::thread([this] {
    timing_.rt = apply_rt_to_this_thread(config_.rt);  // set-up, before the real-time loop
    ready_.store(true, std::memory_order_release);
    run();
  });
  while (!ready_.load(std::memory_order_acquire)) std::this_thread::yield();
  // the steal time before the loop, on the CPU the servo was pinned to (its loop starts at t0, later)
  steal_total_before_ = steal_cpu_before_ = -1;
  if (auto st = read_proc_stat_steal(timing_.rt.cpu)) {
    steal_total_before_ = st.value().total;
    steal_cpu_before_ = st.value().cpu;
  }
  return timing_.rt;
}

void ServoRunner::join() {
  if (config_.max_ticks < 0) stop();
  finish();
}

void ServoRunner::stop() {
  stop_.store(true);
  finish();
}

void ServoRunner::finish() {
  if (!thread_.joinable()) return;
  thread_.join();
  // the steal time since start(), once the loop is over
  if (steal_total_before_ < 0) return;
  if (auto st = read_proc_stat_steal(timing_.rt.cpu)) {
    timing_.steal_all_ms = clock_ticks_ms(st.value().total - steal_total_before_);
    if (steal_cpu_before_ >= 0 && st.value().cpu >= 0) timing_.steal_ms = clock_ticks_ms(st.value().cpu - steal_cpu_before_);
  }
}

void ServoRunner::run() noexcept {
  const bool adaptive = config_.spin_us == ServoRunnerConfig::kAdaptiveSpin;
  const int64_t period_ns = std::llround(1e9 / rates_.servo_hz);
  SpinWindow window(period_ns, adaptive ? static_cast<int64_t>(default_spin_us(rates_.servo_hz)) * 1000
                                         : static_cast<int64_t>(config_.spin_us < 0 ? 0 : config_.spin_us) * 1000);
  const int64_t fixed_spin_ns = adaptive ? 0 : static_cast<int64_t>(config_.spin_us < 0 ? 0 : config_.spin_us) * 1000;
  SpinStats spin{adaptive, 0, INT64_MAX, 0, window.cap_ns()};
  const ThreadSwitches switches0 = this_thread_switches();  // before the loop
  int64_t tick = 0;
  int64_t next_ns = t0_ns_;
  int64_t done_ns = monotonic_ns();
  while (!stop_.load(std::memory_order_relaxed) && (config_.max_ticks < 0 || tick < config_.max_ticks)) {
    // sleep to the deadline (or to just before it, then spin the rest)
    const int64_t spin_ns = adaptive ? window.window_ns() : fixed_spin_ns;
    if (spin_ns < spin.min_ns) spin.min_ns = spin_ns;
    if (spin_ns > spin.max_ns) spin.max_ns = spin_ns;
    const int64_t sleep_to = next_ns - spin_ns;
    sleep_until_ns(sleep_to);
    int64_t woke_ns = monotonic_ns();
    if (done_ns < sleep_to) {  // it did sleep: how late the sleep returned
      timing_.sleep_late.add(woke_ns - sleep_to);
      if (adaptive) window.add(woke_ns - sleep_to);
    }
    while (woke_ns < next_ns) woke_ns = monotonic_ns();
    const int64_t wake_latency_ns = woke_ns - next_ns;
    timing_.wake_latency.add(wake_latency_ns);
    servo_->set_wake_latency_ns(wake_latency_ns);
    servo_->tick(tick, rates_.tick_time_s(tick));
    done_ns = monotonic_ns();
    timing_.compute.add(done_ns - woke_ns);
    ticks_.store(tick + 1, std::memory_order_relaxed);
    // next deadline; periods already past are skipped whole, counted and classified
    ++tick;
    next_ns += period_ns;
    if (done_ns > next_ns) {
      const int64_t missed = (done_ns - next_ns) / period_ns + 1;
      const bool stall = overrun_is_stall(wake_latency_ns, done_ns - woke_ns);
      if (timing_.overrun_ticks_recorded < ServoTiming::kOverrunTicks) {
        timing_.first_overrun_stalls[static_cast<std::size_t>(timing_.overrun_ticks_recorded)] = stall;
        timing_.first_overrun_ticks[static_cast<std::size_t>(timing_.overrun_ticks_recorded++)] = tick;
      }
      timing_.overruns += missed;
      ++timing_.overrun_events;
      if (stall) {
        timing_.stall_overruns += missed;
        ++timing_.stall_events;
      }
      tick += missed;
      next_ns += missed * period_ns;
    }
  }
  // after the loop: what was taken from the thread, and the window used
  const ThreadSwitches switches1 = this_thread_switches();
  if (switches0.involuntary >= 0 && switches1.involuntary >= 0) {
    timing_.involuntary_switches = switches1.involuntary - switches0.involuntary;
    timing_.voluntary_switches = switches1.voluntary - switches0.voluntary;
  }
  spin.final_ns = adaptive ? window.window_ns() : fixed_spin_ns;
  if (spin.min_ns == INT64_MAX) spin.min_ns = spin.max_ns = spin.final_ns;
  timing_.spin = spin;
  finished_.store(true, std::memory_order_release);
}

}  // namespace palpate
