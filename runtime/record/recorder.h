#pragma once
/// Recorder: runs a scene through servo, frame stage, renderer and PNG writer, in lockstep (virtual clock,
/// reproducible) or realtime (threads on the wall clock), and writes frames/, haptic.csv and summary.json.

#include <atomic>
#include <string>
#include <vector>

#include "core/aabb.h"
#include "core/rates.h"
#include "core/result.h"
#include "core/scene.h"
#include "haptics/servo/servo_runner.h"
#include "render/camera.h"
#include "render/png_io.h"
#include "runtime/record/scene_view.h"

namespace palpate {

class LiveFeed;
class BrowserLink;
struct RecordPlan;


/// PNG encoder threads of a lockstep recording (realtime recordings use one).
inline constexpr int kLockstepPngThreads = 2;

/// How to run a recording (command-line overrides of the scene).
struct RecordOptions {
  std::string out_dir;           ///< output folder (created)
  bool override_mode = false;    ///< use `mode` instead of the scene's run_mode
  RunMode mode = RunMode::kLockstep;
  double duration_s = 0.0;       ///< > 0 overrides the scene's duration
  bool quiet = false;            ///< no progress line
  bool render = true;            ///< false: no GL, no frames (sim and haptics only)
  bool full_redraw = false;      ///< draw the whole mesh every frame (no cached static layer; same pixels)
  std::string device;            ///< device override ("scripted", ...); empty = the scene's driver
  bool realtime_flags = false;   ///< --spin-us or --priority given (said when the run is lockstep)
  double servo_rate_hz = 0.0;    ///< > 0 overrides the scene's servo.rate_hz: servo ticks per second (lockstep: per
                                 ///< scene-second); device, servo period, passivity guard and bound, and velocity
                                 ///< estimate all follow it
  int spin_us = -1;              ///< realtime: spin this long before each servo deadline; -1 = adaptive (SpinWindow)
  int fifo_priority = 80;        ///< realtime: SCHED_FIFO priority for the servo, 0 = normal scheduling
  int servo_cpu = -1;            ///< realtime: CPU to pin the servo to, -1 = the last allowed CPU
  bool lock_memory = true;       ///< realtime: mlockall before starting
  std::string video_path;        ///< MP4 of the rendered frames (H.264, yuv420p, frame rate); empty = none
  bool video_optional = false;   ///< a video that cannot be made is a warning (video on by default), not an error
  LiveFeed* live = nullptr;      ///< live view fed by the sim thread while recording (null = none); finished at the end
  BrowserLink* browser = nullptr;///< the live page's input for --device browser (null = none); outlives the recording
  int png_threads = 0;           ///< PNG encoder threads; 0 = kLockstepPngThreads in lockstep, 1 in realtime
  PngCodec png_codec = PngCodec::kLibdeflate;  ///< the frames' compressor (comparisons: bench png --record)
  bool png_keep_alpha = false;   ///< RGBA frames even when opaque (comparisons: the format before RGB frames)
  std::vector<HapticSample>* samples = nullptr;  ///< also keeps haptic.csv's rows here, as they are logged (null:
                                                 ///< none; e.g. the Python module's arrays)
  const std::atomic<bool>* stop = nullptr;  ///< set (e.g. by a signal handler) to end the run after the frame under
                                            ///< way, keeping and finishing every output (null = run to the end)
};

/// What a finished recording reports (also written to summary.json).
struct RecordResult {
  std::string summary_path;
  std::string summary_json;      ///< the summary as written
  int frames_written = 0;
  std::string video_path;        ///< the MP4 written, empty when none
  std::string state_hash;        ///< lockstep only
  ServoTiming servo_timing;      ///< realtime: the servo's timing (lockstep: compute time only)
  LatencyHistogram frame_latency;///< realtime: 60 Hz loop wake latency
  int64_t frames_late = 0;       ///< realtime: frames started more than a period late
  int64_t frames_dropped = 0;    ///< realtime: frames not rendered because the writer was full
  int64_t nan_events = 0;        ///< frames whose lattice state became non-finite (and was reset)
  int64_t divergence_events = 0; ///< frames whose lattice diverged (and was reset)
  std::string no_contact;        ///< when no force was ever sent: why ("no contact in 4.0 s: ..."), else empty
  std::string tool_inside;       ///< touch mode: when the free tool was deep inside the object (tool_inside_note)
  std::string mesh_notice;       ///< what the load turned outward ("turned 12 of 12 triangles outward: ..."), else empty
  std::string interrupted;       ///< RecordOptions::stop ended the run: where, and what was kept; else empty
};

/// Runs a planned recording (record_plan.h: plan_record, then check_plan_outputs). Errors (GL failure, write
/// failures) name the culprit; files already written stay whole.
Result<RecordResult> record_planned(const RecordPlan& plan, const RecordOptions& options);

/// Plans, checks and runs the recording of `scene` with `options`: nothing in the output folder is touched when
/// the plan or its outputs are refused.
Result<RecordResult> record_scene(const Scene& scene, const RecordOptions& options);

}  // namespace palpate
