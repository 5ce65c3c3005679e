#pragma once
/// `palpate bench feel --hands N MODEL...`: seeded random hands on any model — presses to the device's force limit,
/// strokes at 1-200 mm/s over whatever the surface has there (creases, corners, thin parts), lift-offs and
/// re-entries, grabs pulled and shaken sideways, blade passes; point and sphere tools, soft and stiff materials,
/// with and without friction — each run in lockstep and judged as a hand feels it: the god-object's invariant (no
/// tick with a free tool or a held proxy inside the object), steps beyond the device's motion on every contact tick
/// (event ticks excused only up to the jump limit), lateral flips, buzz, energy into the hand, NaN.
/// Thread: any (off the real-time path).

#include <cstdint>
#include <string>
#include <vector>

namespace palpate {

/// What to run.
struct HandFuzzOptions {
  std::vector<std::string> models;  ///< mesh files (anything `palpate info` reads)
  int hands = 10;                   ///< hands per model
  uint64_t seed = 1;                ///< the first hand's seed; hand i of a model uses seed + i
  std::string json_path;            ///< write every hand's figures as JSON here when set
  std::string keep_dir;             ///< write the scene of every hand that fails here when set
  double step_threshold_N = 0.1;    ///< a wild step: above this
  double excess_threshold_N = 0.02; ///< and beyond the device's motion by more than this
  double force_shading_deg = -1.0;  ///< >= 0: every hand's device.force_shading_deg (else the scene default)
};

/// Runs the hands, prints a line per hand that fails, a table per model and overall; returns the exit code (0 when
/// every hand ran, whatever it found; 1 on an error).
int run_hand_fuzz(const HandFuzzOptions& options);

}  // namespace palpate
