#pragma once
/// `palpate bench scale`: a scene's interaction recorded in lockstep (rendering and PNG included) on its model
/// midpoint-subdivided 0..N times, with the cached static layer and with a full redraw of every frame, each run
/// in its own process so its peak memory is its own.

#include <string>

#include "core/result.h"

namespace palpate {

/// What to run and where to write. Plain data.
struct BenchScaleOptions {
  int max_subdivisions = 3;     ///< sizes: the model subdivided 0..max_subdivisions times (4x triangles each)
  double duration_s = 0.0;      ///< > 0 overrides the scene's duration
  bool full_redraw = true;      ///< also record each size with a full redraw of every frame, beside it
  std::string json_path;        ///< write the rows as JSON here when not empty
  std::string plot_path;        ///< write ms per frame against triangles (log-log) as PNG here when not empty
  bool quiet = false;           ///< no progress lines on stderr
};

/// Runs every size; returns the table as text. Errors name the scene, a failed run or an output path.
Result<std::string> run_bench_scale(const std::string& scene_path, const BenchScaleOptions& options);

}  // namespace palpate
