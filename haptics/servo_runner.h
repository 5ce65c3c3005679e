#pragma once
/// ServoRunner: runs Servo::tick on its own thread at a fixed rate, paced by absolute deadlines
/// (clock_nanosleep TIMER_ABSTIME, next += period), optionally sleeping to just before the deadline and
/// spinning the rest; measures wake latency and compute time, counts and locates overruns.

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

#include "haptics/latency_histogram.h"
#include "haptics/rt_setup.h"
#include "haptics/servo.h"

namespace palpate {

/// The default sleep-then-spin window at rate_hz: 100 us, but never more than a quarter of the period, so the
/// thread sleeps in every period (a thread that never sleeps is stopped by the kernel's real-time throttling).
inline int default_spin_us(double rate_hz) {
  const double quarter_us = 0.25e6 / rate_hz;
  return quarter_us < 100.0 ? static_cast<int>(quarter_us) : 100;
}

/// How the servo thread runs.
struct ServoRunnerConfig {
  double rate_hz = 1000.0;  ///< tick rate
  int spin_us = 0;          ///< sleep until deadline - spin_us, then spin (0 = sleep only)
  RtRequest rt;             ///< priority, pinning (memory locking is the caller's, process-wide)
  int64_t max_ticks = -1;   ///< the thread ends by itself once this many periods have passed; -1 = run until stop()
};

/// Timing figures of a realtime servo run; kept without allocating.
struct ServoTiming {
  static constexpr int kOverrunTicks = 8;
  LatencyHistogram wake_latency;    ///< actual - intended wake time
  LatencyHistogram compute;         ///< time inside tick()
  int64_t overruns = 0;             ///< periods missed (skipped whole)
  std::array<int64_t, kOverrunTicks> first_overrun_ticks{};  ///< tick numbers of the first overruns
  int overrun_ticks_recorded = 0;   ///< entries used in first_overrun_ticks
  RtGrant rt;                       ///< what the system granted
};

/// Owns the servo thread. Not copyable. Thread: start/stop from the controlling thread.
class ServoRunner {
 public:
  /// Ticks `servo` at config.rate_hz until stop(); scene time t = tick / rate_hz from start().
  ServoRunner(Servo* servo, const ServoRunnerConfig& config);
  ~ServoRunner();
  ServoRunner(const ServoRunner&) = delete;
  ServoRunner& operator=(const ServoRunner&) = delete;

  /// Starts the thread, waits until it has applied its real-time settings, and returns what was granted;
  /// tick 0 is due at monotonic time t0_ns.
  const RtGrant& start(int64_t t0_ns);
  /// Asks the thread to finish and joins it.
  void stop();
  /// Waits for a thread with max_ticks to end by itself (every period ticked or counted as missed).
  void join();
  /// Ticks completed so far (any thread).
  int64_t ticks() const noexcept { return ticks_.load(std::memory_order_relaxed); }
  /// Timing, valid after stop().
  const ServoTiming& timing() const noexcept { return timing_; }

 private:
  void run() noexcept;  // Thread: servo

  Servo* servo_;
  ServoRunnerConfig config_;
  int64_t period_ns_;
  int64_t t0_ns_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<bool> ready_{false};
  std::atomic<int64_t> ticks_{0};
  ServoTiming timing_;
  std::thread thread_;
};

}  // namespace palpate
