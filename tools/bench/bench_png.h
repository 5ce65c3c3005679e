#pragma once
/// `palpate bench png`: PNG encoders side by side on a recording's own frames — libpng + zlib as RGBA (the
/// format before RGB frames) and as RGB, and libdeflate as RGB — each frame decoded back and compared; with
/// --record, whole lockstep recordings (with their default MP4) with each frame-writing configuration in turn
/// (wall per scene-second).

#include <string>

#include "core/result.h"

namespace palpate {

/// What to run.
struct BenchPngOptions {
  std::string folder;    ///< a recording folder (frames/frame_*.png) or a folder of frame_*.png; empty with record
  std::string record;    ///< scene to record with each writer configuration, reps times, interleaved
  std::string out_dir = "out/bench_png";  ///< recordings go to <out_dir>/<configuration>
  int frames = 60;       ///< at most this many frames, evenly spread over the recording
  int repetitions = 3;   ///< passes over the frames; every encoder encodes each frame once per pass
  std::string json_path; ///< write JSON here when set
};

/// Runs the comparison and returns the table (errors name the folder or frame).
Result<std::string> run_bench_png(const BenchPngOptions& options);

}  // namespace palpate
