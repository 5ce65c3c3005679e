#pragma once
/// Recorder: runs a scene through servo, frame stage, renderer and PNG writer, in lockstep (virtual clock,
/// reproducible) or realtime (threads on the wall clock), and writes frames/, haptic.csv and summary.json.

#include <string>

#include "core/result.h"
#include "core/scene.h"

namespace palpate {

/// How to run a recording (command-line overrides of the scene).
struct RecordOptions {
  std::string out_dir;           ///< output folder (created)
  bool override_mode = false;    ///< use `mode` instead of the scene's run_mode
  RunMode mode = RunMode::kLockstep;
  double duration_s = 0.0;       ///< > 0 overrides the scene's duration
  bool quiet = false;            ///< no progress line
  bool render = true;            ///< false: no GL, no frames (sim and haptics only)
  std::string device;            ///< device override ("scripted", ...); empty = the scene's driver
};

/// What a finished recording reports (also written to summary.json).
struct RecordResult {
  std::string summary_path;
  std::string summary_json;      ///< the summary as written
  int frames_written = 0;
  std::string state_hash;        ///< lockstep only
};

/// Runs the recording. Errors (unwritable output, GL failure, write failures) name the culprit;
/// files already written stay whole.
Result<RecordResult> record_scene(const Scene& scene, const RecordOptions& options);

}  // namespace palpate
