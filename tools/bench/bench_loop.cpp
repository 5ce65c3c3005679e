#include "tools/bench/bench_loop.h"

#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/clock.h"
#include "core/scene.h"
#include "haptics/servo/servo_runner.h"
#include "tools/bench/plot.h"
#include "runtime/session/device_factory.h"
#include "runtime/live/live_feed.h"
#include "runtime/live/live_server.h"
#include "runtime/session/model.h"
#include "runtime/record/recorder.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;

/// One run's figures.
struct LoopRun {
  double rate_hz = 0;
  std::string load;
  int spin_us = 0;  // the window at the end of the run (the adaptive one moves), us
  ServoTiming timing;
  LatencyHistogram frame_latency;
  int64_t frames_late = 0, frames_dropped = 0;
  int64_t ticks = 0;
  bool live = false;             // the live view was served to a client during the run
  int64_t live_frames_sent = 0;  // frames the client received
};

// The servo alone: a real device driver and the real surface patch of the scene, nothing else running
// except a light drain of the sample queue.
Status run_servo_alone(const Scene& scene, const BenchLoopOptions& o, int spin_us, LoopRun* out) {
  auto model = load_model(scene);
  if (!model) return model.error();
  auto device = make_device(scene, "");
  if (!device) return device.error();
  Session session(scene, model.value(), device.value().get());
  session.frame(0, false);  // publishes the surface patch around the tool's start
  std::string why;
  lock_process_memory(&why);
  ServoRunnerConfig cfg;
  cfg.spin_us = spin_us;
  cfg.rt.fifo_priority = o.priority;
  ServoRunner runner(&session.servo(), scene.rates, cfg);
  const int64_t t0 = monotonic_ns() + 5'000'000;
  runner.start(t0);
  HapticSample s;
  while (monotonic_ns() < t0 + static_cast<int64_t>(o.seconds * 1e9)) {
    while (session.samples().try_pop(&s)) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  runner.stop();
  out->timing = runner.timing();
  out->ticks = runner.ticks();
  return Ok{};
}

// spin_us: the window, or ServoRunnerConfig::kAdaptiveSpin
Status run_one(const Scene& scene, const BenchLoopOptions& o, double rate_hz, int spin_us, bool live, LoopRun* out) {
  out->rate_hz = rate_hz;
  out->load = live ? o.load + "+live" : o.load;
  out->live = live;
  BenchLoopOptions oo = o;
  oo.rate_hz = rate_hz;
  if (o.load == "none") {
    Scene at = scene;  // the servo at this run's rate
    at.rates.servo_hz = rate_hz;
    auto st = run_servo_alone(at, oo, spin_us, out);
    out->spin_us = static_cast<int>(out->timing.spin.final_ns / 1000);
    return st;
  }
  RecordOptions ro;
  ro.out_dir = (fs::temp_directory_path() / ("palpate_bench_loop_" + std::to_string(getpid()))).string();
  ro.override_mode = true;
  ro.mode = RunMode::kRealtime;
  ro.duration_s = o.seconds;
  ro.quiet = true;
  ro.render = o.load == "record";
  ro.servo_rate_hz = rate_hz;
  ro.spin_us = spin_us;
  ro.fifo_priority = o.priority;
  std::unique_ptr<LiveFeed> feed;
  std::unique_ptr<LiveServer> server;
  std::unique_ptr<LivePageClient> client;
  if (live) {
    feed = std::make_unique<LiveFeed>(scene.render.width, scene.render.height, o.scene, "realtime");
    server = std::make_unique<LiveServer>(feed.get());
    if (auto st = server->start(ServeAddress{"127.0.0.1", 0}); !st) return st.error();
    client = std::make_unique<LivePageClient>(server->port());
    ro.live = feed.get();
  }
  auto r = record_scene(scene, ro);
  client.reset();
  if (server) {
    server->stop();
    out->live_frames_sent = server->frames_sent();
  }
  std::error_code ec;
  fs::remove_all(ro.out_dir, ec);
  if (!r) return r.error();
  out->timing = r.value().servo_timing;
  out->frame_latency = r.value().frame_latency;
  out->frames_late = r.value().frames_late;
  out->frames_dropped = r.value().frames_dropped;
  out->ticks = out->timing.wake_latency.count();
  out->spin_us = static_cast<int>(out->timing.spin.final_ns / 1000);
  return Ok{};
}

// null for the figures that could not be read (-1)
template <class T>
nlohmann::json unknown_if_negative(T v) {
  return v < 0 ? nlohmann::json() : nlohmann::json(v);
}

nlohmann::json to_json(const LoopRun& r) {
  const auto& w = r.timing.wake_latency;
  const auto& s = r.timing.sleep_late;
  nlohmann::json buckets = nlohmann::json::array();
  for (int i = 0; i < LatencyHistogram::kBuckets; ++i)
    if (w.bucket(i) > 0) buckets.push_back({i, w.bucket(i)});
  return {{"rate_hz", r.rate_hz},
          {"load", r.load},
          {"spin_us", r.spin_us},
          {"ticks", r.ticks},
          {"latency_us", {{"p50", w.quantile_us(0.5)}, {"p99", w.quantile_us(0.99)}, {"p999", w.quantile_us(0.999)},
                          {"max", w.max_us()}, {"over_2ms", w.overflow()}, {"histogram_1us", buckets}}},
          {"compute_us", {{"p50", r.timing.compute.quantile_us(0.5)}, {"p99", r.timing.compute.quantile_us(0.99)},
                          {"max", r.timing.compute.max_us()}}},
          {"overruns", r.timing.overruns},
          {"overrun_events", r.timing.overrun_events},
          {"stall_overruns", r.timing.stall_overruns},
          {"stall_events", r.timing.stall_events},
          {"stall_threshold_us", kStallNs / 1000},
          {"spin", {{"adaptive", r.timing.spin.adaptive}, {"final_us", r.timing.spin.final_ns / 1000},
                    {"min_us", r.timing.spin.min_ns / 1000}, {"max_us", r.timing.spin.max_ns / 1000},
                    {"cap_us", r.timing.spin.cap_ns / 1000}}},
          {"sleep_late_us", {{"p50", s.quantile_us(0.5)}, {"p99", s.quantile_us(0.99)}, {"max", s.max_us()},
                             {"count", s.count()}}},
          {"steal_ms", unknown_if_negative(r.timing.steal_ms)},
          {"steal_all_cpus_ms", unknown_if_negative(r.timing.steal_all_ms)},
          {"involuntary_switches", unknown_if_negative(r.timing.involuntary_switches)},
          {"voluntary_switches", unknown_if_negative(r.timing.voluntary_switches)},
          {"sched_fifo", r.timing.rt.fifo},
          {"cpu", r.timing.rt.cpu},
          {"frame_latency_us", {{"p50", r.frame_latency.quantile_us(0.5)}, {"p99", r.frame_latency.quantile_us(0.99)},
                                {"max", r.frame_latency.max_us()}}},
          {"frames_late", r.frames_late},
          {"frames_dropped", r.frames_dropped},
          {"live", r.live},
          {"live_frames_sent", r.live_frames_sent}};
}

// "-" for a figure that could not be read
std::string figure(double v, const char* format) {
  if (v < 0) return "-";
  char b[32];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

void print_header() {
  std::printf("%8s %-11s %5s %8s %7s %7s %7s %9s %7s %9s %6s %6s %6s %8s %8s %8s %8s %6s %6s\n", "rate_hz", "load",
              "spin", "ticks", "p50_us", "p99_us", "p999_us", "max_us", "slp_p99", "overruns", "ovr_ev", "stalls",
              "stl_ev", "steal_ms", "invol_cs", "cmp_p50", "cmp_p99", "f_late", "f_drop");
}

void print_row(const LoopRun& r) {
  const auto& w = r.timing.wake_latency;
  const std::string spin = std::to_string(r.spin_us) + (r.timing.spin.adaptive ? "a" : "");
  std::printf("%8.0f %-11s %5s %8lld %7.0f %7.0f %7.0f %9.1f %7.0f %9lld %6lld %6lld %6lld %8s %8s %8.0f %8.0f %6lld "
              "%6lld\n",
              r.rate_hz, r.load.c_str(), spin.c_str(), static_cast<long long>(r.ticks), w.quantile_us(0.5),
              w.quantile_us(0.99), w.quantile_us(0.999), w.max_us(), r.timing.sleep_late.quantile_us(0.99),
              static_cast<long long>(r.timing.overruns), static_cast<long long>(r.timing.overrun_events),
              static_cast<long long>(r.timing.stall_overruns), static_cast<long long>(r.timing.stall_events),
              figure(r.timing.steal_ms, "%.0f").c_str(),
              figure(static_cast<double>(r.timing.involuntary_switches), "%.0f").c_str(),
              r.timing.compute.quantile_us(0.5), r.timing.compute.quantile_us(0.99),
              static_cast<long long>(r.frames_late), static_cast<long long>(r.frames_dropped));
  if (r.live) std::printf("         (live view: %lld frames sent to the client)\n", static_cast<long long>(r.live_frames_sent));
  std::fflush(stdout);
}

}  // namespace

double highest_clean_rate(const std::vector<double>& rates_hz, const std::vector<long long>& overruns) {
  double best = 0.0;
  for (std::size_t i = 0; i < rates_hz.size() && i < overruns.size(); ++i) {
    if (overruns[i] != 0) break;
    best = rates_hz[i];
  }
  return best;
}

double highest_rate_clean_but_stalls(const std::vector<double>& rates_hz, const std::vector<long long>& overruns,
                                     const std::vector<long long>& stall_overruns) {
  std::vector<long long> own;  // the loop's own overruns at each rate
  for (std::size_t i = 0; i < overruns.size() && i < stall_overruns.size(); ++i)
    own.push_back(overruns[i] - stall_overruns[i]);
  return highest_clean_rate(rates_hz, own);
}

int run_bench_loop(const BenchLoopOptions& o) {
  // outputs are checked before the runs: never a device or a link replaced after minutes of measuring
  Status targets = o.json_path.empty() ? Status(Ok{}) : check_output_target(o.json_path, "bench json");
  if (targets.ok() && !o.plot_path.empty()) targets = check_plot_targets(o.plot_path);
  if (!targets) {
    std::fprintf(stderr, "palpate: bench loop: %s\n", targets.error().message.c_str());
    return 1;
  }
  auto scene = load_scene(o.scene);
  if (!scene) {
    std::fprintf(stderr, "palpate: %s\n", scene.error().message.c_str());
    return 1;
  }
  report_scene_warnings(scene.value(), stderr);
  const double one_rate_hz = o.rate_hz > 0.0 ? o.rate_hz : scene.value().rates.servo_hz;
  std::vector<double> rates = o.sweep ? std::vector<double>{1000, 2000, 5000, 10000} : std::vector<double>{one_rate_hz};
  std::printf("servo loop: scene %s, %.1f s per run, load %s\n", o.scene.c_str(), o.seconds, o.load.c_str());
  print_header();
  std::vector<LoopRun> runs;
  // per rate, of the first run (the --spin-us window, without the live view): all overruns, and the loop's own
  // (those not from stalls)
  std::vector<long long> overruns, stall_overruns;
  if (o.live && o.load != "record") {
    std::fprintf(stderr, "palpate: bench loop: --live needs --load record (the live view shows rendered frames)\n");
    return 2;
  }
  // the --spin-us window (adaptive when unset), then each --spin-compare window, side by side at each rate
  std::vector<int> windows{o.spin_us >= 0 ? o.spin_us : ServoRunnerConfig::kAdaptiveSpin};
  windows.insert(windows.end(), o.spin_compare.begin(), o.spin_compare.end());
  for (double rate : rates) {
    for (std::size_t w = 0; w < windows.size(); ++w) {
      // with --live: the same run without, then with the live view, side by side
      for (const bool live : o.live ? std::vector<bool>{false, true} : std::vector<bool>{false}) {
        LoopRun r;
        if (auto st = run_one(scene.value(), o, rate, windows[w], live, &r); !st) {
          std::fprintf(stderr, "palpate: bench loop: %s\n", st.error().message.c_str());
          return 1;
        }
        print_row(r);
        if (w == 0 && !live) {
          overruns.push_back(static_cast<long long>(r.timing.overruns));
          stall_overruns.push_back(static_cast<long long>(r.timing.stall_overruns));
        }
        runs.push_back(r);
      }
    }
  }
  std::printf("spin: window (us) at the end of the run, a = adaptive; slp_p99: how late the sleep returned (p99, us);\n"
              "overruns: periods missed, in ovr_ev events; stalls: periods missed in overruns that woke or ran > %lld us "
              "late, in stl_ev events;\nsteal_ms: steal time of the servo's "
              "CPU (/proc/stat, 10 ms resolution); invol_cs: the servo thread's involuntary context switches\n",
              static_cast<long long>(kStallNs / 1000));
  const double best_rate = highest_clean_rate(rates, overruns);
  const double best_but_stalls = highest_rate_clean_but_stalls(rates, overruns, stall_overruns);
  if (o.sweep) {
    if (best_rate > 0.0) std::printf("highest rate with no overruns at it and every lower rate: %.0f Hz\n", best_rate);
    else std::printf("highest rate with no overruns at it and every lower rate: none (%.0f Hz overran)\n", rates.front());
    if (best_but_stalls != best_rate) {
      if (best_but_stalls > 0.0)
        std::printf("highest rate whose overruns, at it and every lower rate, were all stalls the machine took: %.0f Hz\n",
                    best_but_stalls);
      else
        std::printf("highest rate whose overruns, at it and every lower rate, were all stalls the machine took: none\n");
    }
  }
  if (!runs.front().timing.rt.fifo)
    std::printf("note: SCHED_FIFO was refused (%s); figures are for normal scheduling\n",
                runs.front().timing.rt.refused.c_str());
  if (!o.json_path.empty()) {
    nlohmann::json j;
    j["scene"] = o.scene;
    j["runs"] = nlohmann::json::array();
    for (const auto& r : runs) j["runs"].push_back(to_json(r));
    if (o.sweep) {
      j["highest_rate_clean_up_to_hz"] = best_rate;
      j["highest_rate_clean_but_stalls_up_to_hz"] = best_but_stalls;
    }
    if (auto st = write_file_atomic(o.json_path, j.dump(2) + "\n", "bench json"); !st) {
      std::fprintf(stderr, "palpate: bench loop: %s\n", st.error().message.c_str());
      return 1;
    }
  }
  // the plot last: when gnuplot is missing or fails, the table and the JSON are already out
  if (!o.plot_path.empty()) {
    // wake-latency histograms, one per run: ticks per 1 us bucket on log axes (1 us .. 2 ms spans three decades)
    PlotSpec spec;
    spec.title = "servo wake latency, " + o.load + " load";
    char what[256];
    std::snprintf(what, sizeof what, "palpate bench loop --load %s: %zu run(s) of %g s, scene %s", o.load.c_str(),
                  runs.size(), o.seconds, o.scene.c_str());
    spec.what = what;
    spec.x_label = "wake latency (µs, 1 µs buckets)";
    spec.y_label = "ticks per bucket";
    spec.x_column = "latency_us_bucket_centre";
    spec.y_column = "ticks";
    spec.x_min = 0.5;  // the first bucket, [0, 1) us, shows from 0.5 us
    spec.y_min = 0.5;  // a bucket of one tick stands out from the bottom
    const std::array<const char*, 4> colours{"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};
    for (std::size_t r = 0; r < runs.size(); ++r) {
      PlotSeries ser;
      const auto& w = runs[r].timing.wake_latency;
      ser.label = std::to_string(static_cast<int>(runs[r].rate_hz)) + " Hz, spin " + std::to_string(runs[r].spin_us) +
                  " µs" + (runs[r].live ? ", live view" : "") + " (p99 " + std::to_string(static_cast<int>(w.quantile_us(0.99))) + " µs";
      if (w.overflow() > 0) ser.label += ", " + std::to_string(w.overflow()) + " past 2 ms not drawn";
      ser.label += ")";
      ser.colour = colours[r % colours.size()];
      ser.style = PlotStyle::kBoxes;
      for (int i = 0; i < LatencyHistogram::kBuckets; ++i)
        if (w.bucket(i) > 0) {
          ser.x.push_back((i + 0.5) * w.bucket_us());
          ser.y.push_back(static_cast<double>(w.bucket(i)));
          ser.width.push_back(w.bucket_us());
        }
      spec.series.push_back(ser);
    }
    if (write_plot_and_report(spec, o.plot_path) != 0) return 1;
  }
  return 0;
}

}  // namespace palpate
