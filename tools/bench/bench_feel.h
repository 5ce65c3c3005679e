#pragma once
/// `palpate bench feel`: what a hand on the device feels of each scene, from its lockstep tick log — force steps
/// inside contact against what the device's motion explains, ripple while sliding, the steps at contact events, the
/// buzz share above 100 Hz and the energy put into the hand (tools/bench/feel_figures.h).

#include <string>
#include <vector>

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
};

/// Runs the scenes, prints the tables; returns the process exit code.
int run_bench_feel(const BenchFeelOptions& options);

}  // namespace palpate
