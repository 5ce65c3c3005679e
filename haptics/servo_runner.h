#pragma once
/// ServoRunner: runs Servo::tick on its own thread at a fixed rate, paced by absolute deadlines
/// (clock_nanosleep TIMER_ABSTIME, next += period), measuring wake latency and counting overruns.

#include <atomic>
#include <cstdint>
#include <thread>

#include "haptics/latency_histogram.h"
#include "haptics/servo.h"

namespace palpate {

/// Timing figures of a realtime servo run.
struct ServoTiming {
  LatencyHistogram wake_latency;    ///< actual - intended wake time
  LatencyHistogram compute;         ///< time inside tick()
  int64_t overruns = 0;             ///< periods missed (skipped whole)
  bool realtime_priority = false;   ///< SCHED_FIFO was granted
  int priority = 0;                 ///< SCHED_FIFO priority when granted
};

/// Owns the servo thread. Not copyable. Thread: start/stop from the controlling thread.
class ServoRunner {
 public:
  /// Ticks `servo` at rate_hz until stop(); scene time t = tick / rate_hz from start().
  /// fifo_priority > 0 asks for SCHED_FIFO at that priority (falls back to normal scheduling when refused).
  ServoRunner(Servo* servo, double rate_hz, int fifo_priority = 80);
  ~ServoRunner();
  ServoRunner(const ServoRunner&) = delete;
  ServoRunner& operator=(const ServoRunner&) = delete;

  /// Starts the thread; t0_ns is the monotonic time of tick 0.
  void start(int64_t t0_ns);
  /// Asks the thread to finish and joins it.
  void stop();
  /// Ticks completed so far (any thread).
  int64_t ticks() const noexcept { return ticks_.load(std::memory_order_relaxed); }
  /// Timing, valid after stop().
  const ServoTiming& timing() const noexcept { return timing_; }

 private:
  void run() noexcept;  // Thread: servo

  Servo* servo_;
  int64_t period_ns_;
  int64_t t0_ns_ = 0;
  int fifo_priority_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<int64_t> ticks_{0};
  ServoTiming timing_;
  std::thread thread_;
};

}  // namespace palpate
