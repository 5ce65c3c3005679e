#pragma once
/// `palpate bench scale`: a scene's interaction recorded in lockstep (rendering and PNG included) on its model
/// midpoint-subdivided 0..N times, with the cached static layer and with a full redraw of every frame, each run
/// in its own process so its peak memory is its own.

#include <string>

#include "core/result.h"
#include "tools/bench/plot.h"

namespace palpate {

/// What to run and where to write. Plain data.
struct BenchScaleOptions {
  int max_subdivisions = 3;     ///< sizes: the model subdivided 0..max_subdivisions times (4x triangles each)
  double duration_s = 0.0;      ///< > 0 overrides the scene's duration
  bool full_redraw = true;      ///< also record each size with a full redraw of every frame, beside it
  std::string json_path;        ///< write the rows as JSON here when not empty
  std::string plot_path;        ///< ms per frame against triangles (log-log) goes here (FILE.png, FILE.dat, FILE.gp)
  bool quiet = false;           ///< no progress lines on stderr
};

/// Runs every size; returns the table as text, and when `plot` is given and options.plot_path is set fills it with
/// the figure (ms per frame against triangles, log-log) for the caller to draw after printing the table. Errors name
/// the scene, a failed run or an output path.
Result<std::string> run_bench_scale(const std::string& scene_path, const BenchScaleOptions& options,
                                    PlotSpec* plot = nullptr);

}  // namespace palpate
