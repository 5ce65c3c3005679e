#pragma once
/// `palpate bench force`: the force the device feels between 60 Hz sim frames, against a reference that steps the
/// whole lattice at the servo rate — for the hold-last-frame baseline, the static-surface proxy and the multirate
/// local model, and the local model again with each frame's surface taken at once instead of blended over the frame.

#include <string>
#include <vector>

namespace palpate {

/// What to run.
struct BenchForceOptions {
  std::vector<std::string> scenes{"scenes/bunny_touch_springs.json", "scenes/bunny_pull_springs.json"};  ///< lockstep scenes
  std::string json_path;  ///< write JSON here when set
};

/// Runs the comparison, prints a table; returns the process exit code.
int run_bench_force(const BenchForceOptions& options);

}  // namespace palpate
