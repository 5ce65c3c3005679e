#include "haptics/servo/servo_runner.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <random>
#include <thread>

#include "core/clock.h"
#include "haptics/servo/cpu_steal.h"
#include "support/alloc_counter.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

// ---- the adaptive spin window (pure: samples in, window out) ----

TEST(SpinWindow, KeepsTheInitialWindowUntilEnoughSleepsAreSeen) {
  SpinWindow w(1'000'000, 100'000);
  for (int i = 0; i < SpinWindow::kMinSamples - 1; ++i) w.add(5'000);
  EXPECT_EQ(w.window_ns(), 100'000);
  for (int i = 0; i < SpinWindow::kUpdateEvery; ++i) w.add(5'000);
  EXPECT_EQ(w.window_ns(), 6'000 + SpinWindow::kMarginNs);  // 5 us falls in [5, 6) us: its upper edge + margin
}

TEST(SpinWindow, IsThe99thPercentileOfTheSleepsLatenessPlusTheMargin) {
  // 1024 sleeps: 1013 returned 20 us late, 11 returned 150 us late. The 99th percentile is the 1014th of 1024:
  // 150 us, so the window is 151 + 10 us. With one late sleep fewer it is the 20 us bucket: 21 + 10 us.
  SpinWindow a(1'000'000, 100'000);
  for (int i = 0; i < 1013; ++i) a.add(20'000);
  for (int i = 0; i < 11; ++i) a.add(150'000);
  ASSERT_EQ(a.samples() % SpinWindow::kUpdateEvery, 0);
  EXPECT_EQ(a.window_ns(), 151'000 + SpinWindow::kMarginNs);
  SpinWindow b(1'000'000, 100'000);
  for (int i = 0; i < 1014; ++i) b.add(20'000);
  for (int i = 0; i < 10; ++i) b.add(150'000);
  EXPECT_EQ(b.window_ns(), 21'000 + SpinWindow::kMarginNs);
}

TEST(SpinWindow, FollowsTheRecentSleepsAndForgetsOldOnes) {
  SpinWindow busy(1'000'000, 100'000);
  for (int i = 0; i < SpinWindow::kSamples; ++i) busy.add(30'000);
  EXPECT_EQ(busy.window_ns(), 31'000 + SpinWindow::kMarginNs);
  // the machine got busier: once the ring holds only the new sleeps, the window grows to them
  for (int i = 0; i < SpinWindow::kSamples; ++i) busy.add(120'000);
  EXPECT_EQ(busy.window_ns(), 121'000 + SpinWindow::kMarginNs);
  SpinWindow w(1'000'000, 100'000);
  for (int i = 0; i < SpinWindow::kSamples; ++i) w.add(120'000);
  EXPECT_EQ(w.window_ns(), 121'000 + SpinWindow::kMarginNs);
  // the machine got quieter: once the ring holds only the new sleeps, the window shrinks to them
  for (int i = 0; i < SpinWindow::kSamples; ++i) w.add(30'000);
  EXPECT_EQ(w.window_ns(), 31'000 + SpinWindow::kMarginNs);
}

TEST(SpinWindow, NeverPassesTheCapAndAlwaysLeavesASleep) {
  // at 10 kHz the cap is 60 % of 100 us; at 1 kHz 200 us (not 600)
  EXPECT_EQ(max_spin_window_ns(100'000), 60'000);
  EXPECT_EQ(max_spin_window_ns(200'000), 120'000);
  EXPECT_EQ(max_spin_window_ns(1'000'000), 200'000);
  EXPECT_EQ(SpinWindow(100'000, 500'000).window_ns(), 60'000);  // an initial window past the cap is clamped
  std::mt19937 rng(7);
  std::uniform_int_distribution<int64_t> late(0, 3'000'000);  // up to 3 ms: past the last bucket too
  for (const double rate : {500.0, 1000.0, 2000.0, 5000.0, 10000.0, 20000.0, 50000.0}) {
    const auto period = static_cast<int64_t>(1e9 / rate);
    SpinWindow w(period, default_spin_us(rate) * 1000LL);
    for (int i = 0; i < 5000; ++i) {
      w.add(late(rng));
      ASSERT_LE(w.window_ns(), w.cap_ns()) << rate;
      ASSERT_LE(w.window_ns(), period * 3 / 5) << rate << " Hz: the thread must sleep 40 % of each period";
      ASSERT_LE(w.window_ns(), 200'000) << rate;
    }
    EXPECT_EQ(w.window_ns(), w.cap_ns()) << rate << " Hz: sleeps this late ask for more than the cap";
  }
}

TEST(SpinWindow, AddingAllocatesNothing) {
  SpinWindow w(100'000, 25'000);
  int64_t allocs = 0;
  {
    test::AllocationGuard guard;
    for (int i = 0; i < 100'000; ++i) w.add((i * 7919) % 700'000);
    allocs = guard.count();
  }
  EXPECT_EQ(allocs, 0);
  EXPECT_EQ(w.samples(), 100'000);
}

// ---- overrun classification ----

TEST(OverrunClassification, StallsAreWakesOrTicksLongerThanTheThreshold) {
  EXPECT_FALSE(overrun_is_stall(30'000, 2'000));    // a late sleep at 10 kHz: the loop's own
  EXPECT_FALSE(overrun_is_stall(120'000, 3'000));
  EXPECT_FALSE(overrun_is_stall(kStallNs, 0));      // at the threshold: still the loop's
  EXPECT_TRUE(overrun_is_stall(kStallNs + 1, 0));
  EXPECT_TRUE(overrun_is_stall(3'500'000, 2'000));  // the CPU taken away for 3.5 ms before the wake
  EXPECT_TRUE(overrun_is_stall(1'000, 1'200'000));  // or in the middle of the tick
  EXPECT_FALSE(overrun_is_stall(300'000, 0, 400'000));
  EXPECT_TRUE(overrun_is_stall(300'000, 0, 200'000));
}

// ---- /proc/stat steal ----

constexpr const char* kProcStat =
    "cpu  10132153 290696 3084719 46828483 16683 0 25195 1750 0 0\n"
    "cpu0 1393280 32966 572056 13343292 6130 0 17875 905 0 0\n"
    "cpu1 1335310 23467 490212 13371856 2745 0 5187 845 0 0\n"
    "intr 199292687 30 9 0 0 0 0 0 0 1\n"
    "ctxt 3203398541\n"
    "cpu11 1 2 3 4 5 6 7 77 0 0\n";

TEST(ProcStatSteal, ReadsTheEighthValueOfTheTotalAndOfTheServosCpu) {
  auto s = parse_proc_stat_steal(kProcStat, 1);
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s.value().total, 1750);
  EXPECT_EQ(s.value().cpu, 845);
  auto s11 = parse_proc_stat_steal(kProcStat, 11);  // "cpu1" is not "cpu11"
  ASSERT_TRUE(s11.ok());
  EXPECT_EQ(s11.value().cpu, 77);
  auto none = parse_proc_stat_steal(kProcStat, -1);
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(none.value().cpu, -1);
  auto missing = parse_proc_stat_steal(kProcStat, 5);  // not listed (offline)
  ASSERT_TRUE(missing.ok());
  EXPECT_EQ(missing.value().total, 1750);
  EXPECT_EQ(missing.value().cpu, -1);
}

TEST(ProcStatSteal, TextWithoutAStealColumnIsAnErrorNamingTheLine) {
  auto old = parse_proc_stat_steal("cpu  1 2 3 4 5 6 7\ncpu0 1 2 3 4 5 6 7\n", 0);
  ASSERT_FALSE(old.ok());
  EXPECT_NE(old.error().message.find("cpu  1 2 3 4 5 6 7"), std::string::npos) << old.error().message;
  EXPECT_NE(old.error().message.find("steal"), std::string::npos) << old.error().message;
  auto no_total = parse_proc_stat_steal("cpu0 1 2 3 4 5 6 7 8\n", 0);
  ASSERT_FALSE(no_total.ok());
  EXPECT_NE(no_total.error().message.find("no \"cpu\" line"), std::string::npos) << no_total.error().message;
  EXPECT_FALSE(parse_proc_stat_steal("cpu  1 2 3 4 5 6 x 8\n", -1).ok());
}

TEST(ProcStatSteal, ClockTicksAreHundredthsOfASecond) {
  EXPECT_DOUBLE_EQ(clock_ticks_ms(4), 40.0);  // USER_HZ is 100 on Linux
}

// ---- the runner: a real thread ----

// A device held still whose read on one given tick (or on every tick) takes `busy_ns` (busy-waiting: the CPU
// stays with the tick).
class SlowReadDevice final : public Device {
 public:
  static constexpr int kEveryRead = -2;
  SlowReadDevice(int slow_read, int64_t busy_ns) : slow_read_(slow_read), busy_ns_(busy_ns) {}
  const DeviceSpecs& specs() const noexcept override { return specs_; }
  bool read(double, DevicePose* out) noexcept override {
    if (reads_++ == slow_read_ || slow_read_ == kEveryRead) {
      const int64_t until = monotonic_ns() + busy_ns_;
      while (monotonic_ns() < until) {
      }
    }
    out->pos_m = Vec3(0, 0, 0.01);
    out->buttons = 0;
    return true;
  }
  void write_force(const Vec3&) noexcept override {}

 private:
  DeviceSpecs specs_;
  int reads_ = 0;
  int slow_read_;
  int64_t busy_ns_;
};

// a servo of default params over the floor, reading a SlowReadDevice
struct RunnerRig : test::ServoRig<SlowReadDevice> {
  RunnerRig(int slow_read, int64_t busy_ns) : ServoRig(ServoParams{}, 100000, Rates{}, slow_read, busy_ns) {
    test::publish_floor(tb.get());
  }
  // the rates with the servo at rate_hz (servo and runner read the same Rates)
  const Rates& at(double rate_hz) {
    rates.servo_hz = rate_hz;
    return rates;
  }
};

ServoRunnerConfig config(int spin_us, int64_t ticks) {
  ServoRunnerConfig c;
  c.spin_us = spin_us;
  c.rt.fifo_priority = 0;  // normal scheduling: a test must not need privileges
  c.max_ticks = ticks;
  return c;
}

TEST(ServoRunner, TheLoopWithTheAdaptiveWindowAllocatesNothing) {
  // every thread counted from after start() (the thread and its set-up exist) until the loop has ended: the loop,
  // the adaptive window's updates and the switch counts after the loop
  RunnerRig rig(-1, 0);
  ServoRunner runner(rig.servo.get(), rig.at(2000.0), config(ServoRunnerConfig::kAdaptiveSpin, 1200));
  runner.start(monotonic_ns() + 2'000'000);
  int64_t allocs = 0;
  {
    test::AllThreadsAllocationGuard guard;
    while (!runner.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    allocs = guard.count();
  }
  runner.join();
  EXPECT_EQ(allocs, 0);
  const ServoTiming& t = runner.timing();
  EXPECT_GE(t.wake_latency.count() + t.overruns, 1200) << "every period ticked or counted as missed";
  EXPECT_TRUE(t.spin.adaptive);
  EXPECT_GE(t.sleep_late.count(), SpinWindow::kMinSamples);  // the window had samples to follow
  EXPECT_LE(t.spin.max_ns, max_spin_window_ns(500'000));
}

TEST(ServoRunner, TicksThatRunLongerThanTheStallThresholdAreCountedAsStalls) {
  // every read busy-waits 1.5 ms at 1 kHz: every tick overruns by at least one period, and its compute
  // (>= 1.5 ms) marks each overrun a stall whatever else the machine does (the wakes after them are on time)
  RunnerRig rig(SlowReadDevice::kEveryRead, 1'500'000);
  ServoRunner runner(rig.servo.get(), rig.at(1000.0), config(100, 100));
  runner.start(monotonic_ns() + 2'000'000);
  runner.join();
  const ServoTiming& t = runner.timing();
  EXPECT_GE(t.overrun_events, 10);
  EXPECT_EQ(t.stall_events, t.overrun_events);
  EXPECT_EQ(t.stall_overruns, t.overruns);
  for (int i = 0; i < t.overrun_ticks_recorded; ++i) EXPECT_TRUE(t.first_overrun_stalls[static_cast<std::size_t>(i)]) << i;
  EXPECT_GE(t.compute.quantile_us(0.5), 1500.0);
  EXPECT_FALSE(t.spin.adaptive);
  EXPECT_EQ(t.spin.final_ns, 100'000);
}

TEST(ServoRunner, RecordsWhatTheMachineTookOverTheRun) {
  // the figures are read before and after the loop: each is known (>= 0), and a loop that sleeps 1 ms-long
  // periods gave up its CPU voluntarily at least once
  RunnerRig rig(-1, 0);
  ServoRunner runner(rig.servo.get(), rig.at(1000.0), config(0, 200));
  runner.start(monotonic_ns() + 2'000'000);
  runner.join();
  const ServoTiming& t = runner.timing();
  EXPECT_GE(t.steal_all_ms, 0.0);
  if (t.rt.cpu >= 0) {
    EXPECT_GE(t.steal_ms, 0.0);  // the CPU it was pinned to
  }
  // /proc/stat rounds each CPU's line and the total line to clock ticks separately, so one CPU's delta can
  // exceed the total's by one tick (e.g. 0.99 -> 1.00 ticks on this CPU while the sum goes 1.49 -> 1.50)
  const double tick_ms = 1000.0 / static_cast<double>(sysconf(_SC_CLK_TCK));
  EXPECT_LE(t.steal_ms, t.steal_all_ms + tick_ms);
  EXPECT_GE(t.involuntary_switches, 0);
  EXPECT_GE(t.voluntary_switches, 1);
}

}  // namespace
}  // namespace palpate
