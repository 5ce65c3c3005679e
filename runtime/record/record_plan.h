#pragma once
/// RecordPlan: everything a recording needs decided before it starts — the scene with the command line's
/// overrides applied (its Rates the run's one copy), the run mode, the device driver, the video policy and every
/// output path — resolved once by plan_record() and checked by check_plan_outputs() before anything in the output
/// folder is touched. The recorder and `palpate record` only read it.

#include <optional>
#include <string>
#include <vector>

#include "core/result.h"
#include "core/scene.h"
#include "runtime/record/recorder.h"

namespace palpate {

/// What becomes of the MP4.
enum class VideoPolicy {
  kNone,      ///< no video (--no-video, --no-render, or none asked)
  kDuring,    ///< encoded while recording, on its own thread
  kAfterRun,  ///< a realtime run's default video: encoded from frames/ after the run (an encoder thread beside the
              ///< servo took its wake latency p99 from 60 us to 409 us on a 2-core machine)
};

/// A recording, decided. Plain data.
struct RecordPlan {
  Scene scene;                     ///< --duration and --servo-rate applied, run_mode the one the run uses
  bool lockstep = true;            ///< scene.run_mode == kLockstep
  std::string mode_from;           ///< why that mode: "scene", "--mode", or "shm device" (its own wall clock)
  bool rate_given = false;         ///< --servo-rate (else the scene's servo.rate_hz)
  bool render = true;              ///< frames drawn (not --no-render)
  DeviceDriver driver = DeviceDriver::kScripted;  ///< the device's driver (--device, else the scene's)
  VideoPolicy video = VideoPolicy::kNone;
  std::string video_path;          ///< the MP4 (empty with kNone)
  bool video_optional = false;     ///< a video that cannot be made is a warning (the default video), not an error
  std::string video_reason;        ///< kNone: why ("--no-video", "--no-render", ...)
  std::string out_dir;             ///< the output folder
  std::string frames_dir;          ///< out_dir/frames (created only when rendering)
  std::string summary_path;        ///< out_dir/summary.json
  std::string haptic_csv_path;     ///< out_dir/haptic.csv
  std::vector<std::string> warnings;  ///< said once before the run (stability, material, flags that do not apply)
};

/// Decides a recording from the scene and the command line's options; reads no file and writes none. Errors name
/// the option and the value: an unknown --device driver, a --video that is one of the recording's own outputs
/// (summary.json, haptic.csv, device_events.csv, a frame under frames/, or the output folder itself).
Result<RecordPlan> plan_record(const Scene& scene, const RecordOptions& options);

/// Checks every output of the plan before anything is written or removed: the output folder is a folder (or can be
/// created), the video's folder exists (or is the output folder) and can be written, the video is not a link or a
/// non-regular file. Reads the file system only.
Status check_plan_outputs(const RecordPlan& plan);

}  // namespace palpate
