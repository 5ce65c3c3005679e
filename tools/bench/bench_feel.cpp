#include "tools/bench/bench_feel.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/scene.h"
#include "haptics/devices/replay_device.h"
#include "tools/bench/feel_figures.h"
#include "tools/bench/plot.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/model.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {

Result<FeelRun> run_scene(const std::string& path, const BenchFeelOptions& o) {
  auto scene = load_scene(path);
  if (!scene) return scene.error();
  report_scene_warnings(scene.value(), stderr);
  if (o.force_shading_deg >= 0.0) scene.value().device.force_shading_deg = o.force_shading_deg;
  auto model = load_model(scene.value());
  if (!model) return model.error();
  return run_feel(scene.value(), model.value(), o);
}

}  // namespace

// one lockstep run of the scene as `palpate record` runs it (no rendering), every tick kept
Result<FeelRun> run_feel(const Scene& sc, const Model& model, const BenchFeelOptions& o) {
  const Rates& rates = sc.rates;
  auto dev = make_device(sc, o.device);
  if (!dev) return dev.error();
  // a replayed hand (a browser or device session recorded in realtime) runs for its log's length: its first to its
  // last row's time, and that last row's tick
  double duration_s = o.duration_s > 0.0 ? o.duration_s : sc.duration_s;
  if (const auto* replay = dynamic_cast<const ReplayDevice*>(dev.value().get()); replay != nullptr && o.duration_s <= 0.0)
    duration_s = replay->duration_s() + sc.rates.servo_period_s();
  Session session(sc, model, dev.value().get());
  FeelRun run;
  run.name = sc.name;
  run.trace.reserve(static_cast<std::size_t>(rates.ticks(duration_s)));
  // a frame that placed or moved the region, or cut, marks the next tick (the first to feel its patch)
  bool had_lattice = false, region_pending = false, cut_pending = false;
  int64_t moves = 0, cut_springs = 0;
  session.run_lockstep(
      duration_s,
      [&](int64_t, double) {
        const FrameStats& st = session.stage().stats();
        const bool has = session.stage().lattice().has_value();
        if ((has && !had_lattice && sc.mode != InteractionMode::kCut) || st.region_moves != moves) region_pending = true;
        if (st.springs_cut != cut_springs) cut_pending = true;
        had_lattice = has;
        moves = st.region_moves;
        cut_springs = st.springs_cut;
      },
      [&](int64_t, double) {
        const HapticSample& s = session.servo().last_sample();
        FeelTick t;
        t.tool_m = s.tool_pos_m;
        t.force_N = s.force_N;
        t.contact = s.contact;
        t.region_changed = region_pending;
        t.cut = cut_pending;
        region_pending = cut_pending = false;
        run.trace.push_back(t);
      });
  const ServoParams& sp = session.servo_params();
  run.settings.period_s = rates.servo_period_s();
  run.settings.coupling_N_per_m = sp.coupling_N_per_m;
  run.settings.damping_Ns_per_m = sp.coupling_damping_Ns_per_m;
  run.settings.step_threshold_N = o.step_threshold_N;
  run.settings.excess_threshold_N = o.excess_threshold_N;
  run.settings.jump_limit_N_per_tick = sp.jump_limit_N_per_tick;
  run.figures = feel_figures(run.trace, run.settings);
  const FrameStats& st = session.stage().stats();
  run.tool_inside_ticks = st.tool_inside_ticks;
  run.proxy_inside_ticks = st.proxy_inside_ticks;
  run.through_first_t_s = st.through_first_t_s;
  run.nan_events = st.nan_events + st.divergence_events;
  run.jump_limit_N_per_tick = sp.jump_limit_N_per_tick;
  return run;
}

nlohmann::json feel_run_json(const FeelRun& r) {
  const FeelFigures& f = r.figures;
  nlohmann::json ev = nlohmann::json::object();
  for (int k = 0; k < kFeelEvents; ++k)
    ev[kFeelEventNames[k]] = {{"count", f.events[k].count}, {"max_step_N", f.events[k].max_step_N},
                              {"max_excess_N", f.events[k].max_excess_N}};
  return {{"scene", r.name},
          {"ticks", f.ticks},
          {"contact_ticks", f.contact_ticks},
          {"steady_ticks", f.steady_ticks},
          {"coupling_N_per_m", r.settings.coupling_N_per_m},
          {"steady", {{"max_step_N", f.max_step_N}, {"p99_step_N", f.p99_step_N}, {"steps_over_threshold", f.steps_over},
                      {"max_excess_N", f.max_excess_N}, {"excess_over_threshold", f.excess_over},
                      {"lateral_flips", f.lateral_flips}}},
          {"sliding", {{"ticks", f.sliding_ticks}, {"ripple", f.ripple}}},
          {"buzz_share_above_hz", {{"hz", r.settings.buzz_hz}, {"share", f.buzz_share}}},
          {"energy_into_hand_J", f.energy_into_hand_J},
          {"events", ev}};
}

namespace {

void print_tables(const std::vector<FeelRun>& runs, const BenchFeelOptions& o) {
  std::printf("steady contact (steps |dF| per tick; excess: beyond k_c |dP_t| + b_c |dv|)\n");
  std::printf("%-20s %7s %7s %8s %8s %7s %9s %7s %6s %8s %7s %8s %10s\n", "scene", "contact", "steady", "max_N",
              "p99_N", ">thr", "excess_N", ">0.02", "flips", "sliding", "ripple", "buzz_%", "energy_mJ");
  for (const FeelRun& r : runs) {
    const FeelFigures& f = r.figures;
    std::printf("%-20s %7lld %7lld %8.4f %8.4f %7lld %9.4f %7lld %6lld %8lld %7.3f %8.3f %10.3f\n", r.name.c_str(),
                static_cast<long long>(f.contact_ticks), static_cast<long long>(f.steady_ticks), f.max_step_N,
                f.p99_step_N, static_cast<long long>(f.steps_over), f.max_excess_N,
                static_cast<long long>(f.excess_over), static_cast<long long>(f.lateral_flips),
                static_cast<long long>(f.sliding_ticks), f.ripple, 100.0 * f.buzz_share, 1e3 * f.energy_into_hand_J);
  }
  std::printf("(>thr: steps above %g N; >0.02: excess above %g N)\n\n", o.step_threshold_N, o.excess_threshold_N);
  std::printf("events: count / largest step on the event tick (N) / largest excess in the %g ms after it (N)\n",
              1e3 * FeelSettings{}.event_window_s);
  std::printf("%-20s", "scene");
  for (int k = 0; k < kFeelEvents; ++k) std::printf(" %20s", kFeelEventNames[k]);
  std::printf("\n");
  for (const FeelRun& r : runs) {
    std::printf("%-20s", r.name.c_str());
    for (int k = 0; k < kFeelEvents; ++k) {
      const FeelEventFigures& e = r.figures.events[k];
      char cell[64];
      if (e.count == 0) std::snprintf(cell, sizeof cell, "-");
      else std::snprintf(cell, sizeof cell, "%lld/%.3f/%.3f", static_cast<long long>(e.count), e.max_step_N, e.max_excess_N);
      std::printf(" %20s", cell);
    }
    std::printf("\n");
  }
}

int write_plots(const std::vector<FeelRun>& runs, const std::string& png) {
  const std::array<const char*, 8> colours{"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                           "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};
  PlotSpec trace;
  trace.title = "force sent, per servo tick";
  trace.what = "palpate bench feel --plot " + png;
  trace.x_label = "scene time (s)";
  trace.y_label = "|F| (N)";
  trace.x_column = "t_s";
  trace.y_column = "force_N";
  trace.log_x = trace.log_y = false;
  trace.key_outside = true;
  PlotSpec spec = trace;
  spec.title = "force spectrum, longest contact stretch (mean removed, Hann window)";
  spec.x_label = "frequency (Hz)";
  spec.y_label = "power (N^2 per bin)";
  spec.x_column = "hz";
  spec.y_column = "power_N2";
  spec.log_x = spec.log_y = true;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    PlotSeries s;
    s.label = runs[i].name;
    s.colour = colours[i % colours.size()];
    s.style = PlotStyle::kLines;
    for (std::size_t k = 0; k < runs[i].trace.size(); ++k) {
      s.x.push_back(static_cast<double>(k) * runs[i].settings.period_s);
      s.y.push_back(runs[i].trace[k].force_N.norm());
    }
    trace.series.push_back(s);
    s.x = runs[i].figures.spectrum_hz;
    s.y = runs[i].figures.spectrum_power;
    if (!s.x.empty()) spec.series.push_back(s);
  }
  const std::string spectrum_png = png.substr(0, png.size() - 4) + "_spectrum.png";
  if (write_plot_and_report(trace, png) != 0) return 1;
  return write_plot_and_report(spec, spectrum_png);
}

}  // namespace

int run_bench_feel(const BenchFeelOptions& o) {
  std::vector<std::string> scenes = o.scenes;
  if (scenes.empty()) {
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(o.scenes_dir, ec))
      if (e.path().extension() == ".json") scenes.push_back(e.path().string());
    if (ec || scenes.empty()) {
      std::fprintf(stderr, "palpate: bench feel: no scenes given and no *.json in '%s'\n", o.scenes_dir.c_str());
      return 1;
    }
    std::sort(scenes.begin(), scenes.end());
  }
  // outputs are checked before the runs
  Status targets = o.json_path.empty() ? Status(Ok{}) : check_output_target(o.json_path, "bench json");
  if (targets.ok() && !o.plot_path.empty()) targets = check_plot_targets(o.plot_path);
  if (targets.ok() && !o.plot_path.empty())
    targets = check_plot_targets(o.plot_path.substr(0, o.plot_path.size() - 4) + "_spectrum.png");
  if (!targets.ok()) {
    std::fprintf(stderr, "palpate: bench feel: %s\n", targets.error().message.c_str());
    return 1;
  }
  std::vector<FeelRun> runs;
  for (const std::string& path : scenes) {
    auto r = run_scene(path, o);
    if (!r) {
      std::fprintf(stderr, "palpate: bench feel: %s\n", r.error().message.c_str());
      return 1;
    }
    runs.push_back(std::move(r.value()));
  }
  print_tables(runs, o);
  if (!o.json_path.empty()) {
    nlohmann::json out{{"step_threshold_N", o.step_threshold_N}, {"excess_threshold_N", o.excess_threshold_N},
                       {"scenes", nlohmann::json::array()}};
    for (const FeelRun& r : runs) out["scenes"].push_back(feel_run_json(r));
    if (auto st = write_file_atomic(o.json_path, out.dump(2) + "\n", "bench json"); !st) {
      std::fprintf(stderr, "palpate: bench feel: %s\n", st.error().message.c_str());
      return 1;
    }
  }
  if (!o.plot_path.empty()) return write_plots(runs, o.plot_path);
  return 0;
}

}  // namespace palpate
