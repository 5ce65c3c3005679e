#pragma once
/// `palpate bench loop`: the servo's loop-rate figures, alone or beside the sim or the full record pipeline.

#include <string>
#include <vector>

namespace palpate {

/// What to run.
struct BenchLoopOptions {
  std::string scene = "scenes/bunny_pull_springs.json";  ///< scene whose device, model and pipeline are used
  double rate_hz = 0.0;                          ///< servo rate; 0 = the scene's (Scene::rates)
  double seconds = 5.0;                          ///< run length per rate
  std::string load = "none";                     ///< none | sim | record
  int spin_us = -1;                              ///< -1 = the adaptive window (the recorder's default)
  std::vector<int> spin_compare;                 ///< fixed windows (us) also run at each rate, side by side
  int priority = 80;                             ///< SCHED_FIFO priority, 0 = normal scheduling
  bool sweep = false;                            ///< try 1, 2, 5, 10 kHz and report the highest without overruns
  bool live = false;                             ///< record load: each run again with the live view served and a
                                                 ///< client fetching frames and figures as its page does
  std::string json_path;                         ///< write JSON here when set
  std::string plot_path;                         ///< draw the wake-latency histogram here when set
};

/// The sweep's verdict: the highest of `rates_hz` (ascending) such that it and every lower rate ran with zero
/// overruns (`overruns[i]` at `rates_hz[i]`); 0 when the lowest rate already overran. A clean rate above one that
/// overran does not count: that run was lucky, not the machine able.
double highest_clean_rate(const std::vector<double>& rates_hz, const std::vector<long long>& overruns);

/// The sweep's second verdict: the same rule applied to the overruns that were not stalls (`overruns[i]` minus
/// `stall_overruns[i]`, ServoTiming's): the highest rate up to which every overrun was a stall the machine took.
double highest_rate_clean_but_stalls(const std::vector<double>& rates_hz, const std::vector<long long>& overruns,
                                     const std::vector<long long>& stall_overruns);

/// Runs the benchmark, prints a table; returns the process exit code (errors on stderr).
int run_bench_loop(const BenchLoopOptions& options);

}  // namespace palpate
