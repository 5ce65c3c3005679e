#pragma once
/// `palpate bench feel`: what a hand on the device feels of each scene, from its lockstep tick log — force steps
/// inside contact against what the device's motion explains, ripple while sliding, the steps at contact events, the
/// buzz share above 100 Hz and the energy put into the hand (tools/bench/feel_figures.h).

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/result.h"
#include "core/scene.h"
#include "tools/bench/feel_figures.h"
#include "runtime/session/model.h"

namespace palpate {

/// What to run.
struct BenchFeelOptions {
  std::vector<std::string> scenes;  ///< lockstep scenes; empty: every *.json in scenes_dir
  std::string scenes_dir = "scenes";///< where the shipped scenes are
  std::string json_path;            ///< write JSON here when set
  std::string plot_path;            ///< FILE.png: force traces; FILE_spectrum.png: force spectra (gnuplot)
  double step_threshold_N = 0.1;    ///< steps counted above this
  double excess_threshold_N = 0.02; ///< steps beyond the explained part counted above this
  std::string device = "scripted";  ///< the hand: scripted, or replay:PATH (a recorded haptic.csv or its folder)
  double duration_s = 0.0;          ///< scene seconds run; 0: the scene's, or the replayed log's whole length
  double force_shading_deg = -1.0;  ///< >= 0: every scene's device.force_shading_deg instead of its own
};

/// One scene's lockstep run as `bench feel` takes it: every tick kept, its figures, and what the frame stage counted.
struct FeelRun {
  std::string name;             ///< the scene's name
  std::vector<FeelTick> trace;  ///< one entry per servo tick
  FeelSettings settings;        ///< the coupling and thresholds the figures were taken with
  FeelFigures figures;          ///< feel_figures(trace, settings)
  int64_t tool_inside_ticks = 0;   ///< touch: free ticks with the tool provably inside the object (FrameStats)
  int64_t proxy_inside_ticks = 0;  ///< touch: contact ticks with the proxy provably inside it
  double through_first_t_s = -1.0; ///< the first of either (-1: none)
  int64_t nan_events = 0;          ///< lattice states reset for going non-finite or diverging
  double jump_limit_N_per_tick = 0.0;  ///< the servo's jump limit (an event tick's excuse)
};

/// Runs scene (its model loaded) in lockstep with the hand options.device names for options.duration_s (or the
/// scene's, or a replayed log's length), no rendering. Errors name the device or the scene.
Result<FeelRun> run_feel(const Scene& scene, const Model& model, const BenchFeelOptions& options);

/// One run's figures as `bench feel --json` writes them for each scene.
nlohmann::json feel_run_json(const FeelRun& run);

/// Runs the scenes, prints the tables; returns the process exit code.
int run_bench_feel(const BenchFeelOptions& options);

}  // namespace palpate
