#pragma once
/// ServoRunner: runs Servo::tick on its own thread at a fixed rate, paced by absolute deadlines
/// (clock_nanosleep TIMER_ABSTIME, next += period), optionally sleeping to just before the deadline and
/// spinning the rest (a fixed window or one that follows how late the sleep returns); measures wake latency and
/// compute time, counts, locates and classifies overruns, and records what the machine took (steal, switches).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <thread>

#include "haptics/servo/latency_histogram.h"
#include "haptics/servo/rt_setup.h"
#include "haptics/servo/servo.h"

namespace palpate {

/// The adaptive window's start at rate_hz, until it has seen enough sleeps: 100 us, but never more than a quarter
/// of the period.
inline int default_spin_us(double rate_hz) {
  const double quarter_us = 0.25e6 / rate_hz;
  return quarter_us < 100.0 ? static_cast<int>(quarter_us) : 100;
}

/// An overrun whose tick woke, or ran, later/longer than this was a stall the machine took (the CPU given to another
/// thread or, on a virtual machine, to another guest), not the loop's own fault: the sleep's wake latency is tens of
/// microseconds and a tick's compute a few.
inline constexpr int64_t kStallNs = 500'000;

/// Whether an overrun with this wake latency and compute time was a stall (either longer than stall_ns).
constexpr bool overrun_is_stall(int64_t wake_latency_ns, int64_t compute_ns, int64_t stall_ns = kStallNs) noexcept {
  return wake_latency_ns > stall_ns || compute_ns > stall_ns;
}

/// The largest spin window at period_ns: 60 % of the period, so the thread sleeps in every period (a thread that
/// never sleeps is stopped by the kernel's real-time throttling), and never more than 200 us: a sleep that returns
/// later than that was held up by the CPU being busy elsewhere, which a longer spin does not fix but pays for.
constexpr int64_t max_spin_window_ns(int64_t period_ns) noexcept {
  const int64_t sixty_percent = period_ns * 3 / 5;
  return sixty_percent < 200'000 ? sixty_percent : 200'000;
}

/// The adaptive spin window: how late the last kSamples sleeps returned (1 us buckets, fixed-size state, no
/// allocation), and a window at their 99th percentile plus a 10 us margin, at most max_spin_window_ns(period).
/// Until kMinSamples sleeps are seen it keeps the initial window. Thread: the servo (one writer).
class SpinWindow {
 public:
  static constexpr int kBuckets = 512;       ///< 1 us each; a later return counts in the last
  static constexpr int kSamples = 1024;      ///< the window follows this many most recent sleeps
  static constexpr int kMinSamples = 256;    ///< before these, the initial window
  static constexpr int kUpdateEvery = 128;   ///< the window is recomputed every this many sleeps
  static constexpr double kQuantile = 0.99;  ///< of the sleep's lateness
  static constexpr int64_t kMarginNs = 10'000;

  /// A window for period_ns starting at initial_ns (clamped to the cap).
  SpinWindow(int64_t period_ns, int64_t initial_ns) noexcept;
  /// Records how late one sleep returned after its target; recomputes the window every kUpdateEvery samples.
  void add(int64_t sleep_late_ns) noexcept;
  /// The window to use now, ns.
  int64_t window_ns() const noexcept { return window_ns_; }
  /// Its upper bound, max_spin_window_ns(period).
  int64_t cap_ns() const noexcept { return cap_ns_; }
  /// Samples seen in all.
  int64_t samples() const noexcept { return added_; }

 private:
  void update() noexcept;
  int64_t cap_ns_;
  int64_t window_ns_;
  int64_t added_ = 0;
  std::array<uint16_t, kSamples> ring_{};   // bucket of each recent sample, oldest overwritten
  std::array<int32_t, kBuckets> counts_{};  // samples per bucket among the recent ones
};

/// How the servo thread runs.
struct ServoRunnerConfig {
  static constexpr int kAdaptiveSpin = -1;
  int spin_us = 0;          ///< sleep until deadline - spin_us, then spin (0 = sleep only, kAdaptiveSpin = SpinWindow)
  RtRequest rt;             ///< priority, pinning (memory locking is the caller's, process-wide)
  int64_t max_ticks = -1;   ///< the thread ends by itself once this many periods have passed; -1 = run until stop()
};

/// The spin window a run used.
struct SpinStats {
  bool adaptive = false;  ///< followed the sleep's lateness (SpinWindow), else fixed
  int64_t final_ns = 0;   ///< at the end of the run
  int64_t min_ns = 0;     ///< smallest and largest used during the run
  int64_t max_ns = 0;
  int64_t cap_ns = 0;     ///< the adaptive window's bound (max_spin_window_ns)
};

/// Timing figures of a realtime servo run; kept without allocating.
struct ServoTiming {
  static constexpr int kOverrunTicks = 8;
  LatencyHistogram wake_latency;    ///< actual - intended wake time
  LatencyHistogram compute;         ///< time inside tick()
  LatencyHistogram sleep_late;      ///< how late each sleep returned after its target (deadline - window)
  int64_t overruns = 0;             ///< periods missed (skipped whole)
  int64_t overrun_events = 0;       ///< ticks that ran past the next deadline (each missed one or more periods)
  int64_t stall_overruns = 0;       ///< of `overruns`, the periods missed in stalls (overrun_is_stall)
  int64_t stall_events = 0;         ///< of `overrun_events`, the stalls
  std::array<int64_t, kOverrunTicks> first_overrun_ticks{};  ///< tick numbers of the first overruns
  std::array<bool, kOverrunTicks> first_overrun_stalls{};  ///< whether each of those was a stall
  int overrun_ticks_recorded = 0;   ///< entries used in first_overrun_ticks
  SpinStats spin;                   ///< the spin window used
  // what the machine took during the run, read before and after the loop (never inside it); -1 = unknown
  double steal_ms = -1;             ///< steal time of the servo's CPU (/proc/stat "cpuN", 10 ms resolution)
  double steal_all_ms = -1;         ///< steal time summed over all CPUs (/proc/stat "cpu")
  int64_t involuntary_switches = -1;  ///< the servo thread's CPU taken from it (getrusage RUSAGE_THREAD)
  int64_t voluntary_switches = -1;    ///< the servo thread's sleeps that gave up the CPU
  RtGrant rt;                       ///< what the system granted
};

/// Owns the servo thread. Not copyable. Thread: start/stop from the controlling thread.
class ServoRunner {
 public:
  /// Ticks `servo` at rates.servo_hz until stop(); scene time t = tick / servo_hz from start(). rates: the run's
  /// (Scene::rates), read when the thread starts; must outlive the runner.
  ServoRunner(Servo* servo, const Rates& rates, const ServoRunnerConfig& config);
  ServoRunner(Servo*, Rates&&, const ServoRunnerConfig&) = delete;
  ~ServoRunner();
  ServoRunner(const ServoRunner&) = delete;
  ServoRunner& operator=(const ServoRunner&) = delete;

  /// Starts the thread, waits until it has applied its real-time settings, and returns what was granted;
  /// tick 0 is due at monotonic time t0_ns.
  const RtGrant& start(int64_t t0_ns);
  /// Asks the thread to finish and joins it (and reads the steal time since start()).
  void stop();
  /// Waits for a thread with max_ticks to end by itself (every period ticked or counted as missed).
  void join();
  /// True once the thread has left its loop and recorded its figures (any thread; join() to read them).
  bool finished() const noexcept { return finished_.load(std::memory_order_acquire); }
  /// Ticks completed so far (any thread).
  int64_t ticks() const noexcept { return ticks_.load(std::memory_order_relaxed); }
  /// Timing, valid after stop().
  const ServoTiming& timing() const noexcept { return timing_; }

 private:
  void run() noexcept;  // Thread: servo
  void finish();        // joins the thread and reads the steal time since start(); controlling thread

  Servo* servo_;
  const Rates& rates_;
  ServoRunnerConfig config_;
  int64_t t0_ns_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<bool> ready_{false};
  std::atomic<bool> finished_{false};
  std::atomic<int64_t> ticks_{0};
  ServoTiming timing_;
  std::thread thread_;
  int64_t steal_total_before_ = -1;  // /proc/stat steal ticks at start(); controlling thread
  int64_t steal_cpu_before_ = -1;
};

}  // namespace palpate
