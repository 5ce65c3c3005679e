#pragma once
/// summary.json of a recording: what ran (scene, mode, model, material, device), what the servo and the frame
/// stage counted, the coupling and the limit that set it, timings, outputs and, in lockstep, the state hash.

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "haptics/devices/device.h"
#include "haptics/servo/latency_histogram.h"
#include "haptics/servo/servo_runner.h"
#include "render/gl_context.h"
#include "render/png_writer.h"
#include "render/renderer.h"
#include "runtime/session/model.h"
#include "runtime/session/session.h"
#include "runtime/record/video_output.h"

namespace palpate {

/// What a recording's driver measured beside the session's own counters. Plain data.
struct RunFigures {
  ServoTiming timing;                         ///< realtime: the servo thread's; lockstep: compute time only
  LatencyHistogram frame_latency{100'000};    ///< realtime: frame start - frame deadline, 100 us buckets to 200 ms
  int64_t frames_late = 0;                    ///< realtime: frames skipped a whole period late
  std::vector<int64_t> skipped_frames;        ///< realtime: their indices (a replay of the run skips them too)
  bool memory_locked = false;                 ///< realtime: mlockall succeeded
  std::string aborted;                        ///< why the run ended before its duration (out of memory), else empty
  std::string interrupted;                    ///< a stop asked for (SIGINT, SIGTERM, SIGHUP): where the run ended, else empty
};

/// Everything summary.json is made of; the pointers are non-null unless said otherwise. Plain data.
struct SummaryInputs {
  const Scene* scene = nullptr;          ///< with the command line's duration applied
  const Model* model = nullptr;
  const Session* session = nullptr;      ///< finished (servo stopped, samples drained)
  const Device* device = nullptr;
  const RunFigures* run = nullptr;
  bool lockstep = true;
  bool rate_given = false;               ///< the servo rate came from --servo-rate (else the scene)
  double startup_s = 0.0;                ///< loading the model
  double wall_s = 0.0;                   ///< the run, wall clock
  const GlContext* gl = nullptr;         ///< null when not rendering
  const Renderer* renderer = nullptr;    ///< null when not rendering
  const PngWriter* writer = nullptr;     ///< null when not rendering
  PngWriterConfig png;
  const RecordingVideo* video = nullptr;
  bool render = true;                    ///< frames were drawn (--no-render: false)
  int64_t haptic_rows = 0;               ///< rows in haptic_csv (the file on disk), 0 when none is kept
  std::string haptic_csv;                ///< the log kept: haptic.csv, haptic.csv.partial, or empty when none
  std::string haptic_error;              ///< why haptic.csv was not completed, empty when it was
  std::string no_contact;                ///< why no force was ever sent, empty when one was
  std::string frames_dir;
};

/// The summary object (written as summary.json, pretty-printed).
nlohmann::json recording_summary(const SummaryInputs& in);

}  // namespace palpate
