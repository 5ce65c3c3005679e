#pragma once
/// Session: the wiring of one run of the pipeline — the sample queue from the servo to the sim thread, the triple
/// buffer of the local model back to the servo, the servo's parameters at the session's rates, the Servo and the
/// FrameStage — owned in one place. Drivers (record, the benchmarks, tool holding, the tests) build a Session and
/// either run it in lockstep (run_lockstep) or hand its servo to a ServoRunner thread and call frame() on the
/// wall clock.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "core/clock.h"
#include "core/controls.h"
#include "core/rates.h"
#include "core/scene.h"
#include "core/spsc_queue.h"
#include "core/triple_buffer.h"
#include "haptics/devices/device.h"
#include "haptics/servo/haptic_sample.h"
#include "haptics/servo/latency_histogram.h"
#include "haptics/servo/local_model.h"
#include "haptics/servo/servo.h"
#include "render/png_writer.h"
#include "render/renderer.h"
#include "render/video_writer.h"
#include "runtime/session/frame_stage.h"
#include "runtime/session/haptic_log.h"
#include "runtime/live/live_feed.h"
#include "runtime/session/lockstep.h"
#include "runtime/session/model.h"

namespace palpate {

/// Where a session's frames and samples go; every pointer may be null (nothing of that kind) and must outlive the
/// session.
struct SessionOutputs {
  Renderer* renderer = nullptr;  ///< draws each frame (the GL context current on the sim thread)
  PngWriter* writer = nullptr;   ///< PNG files of the rendered frames
  HapticLog* log = nullptr;      ///< haptic.csv, one row per servo tick
  VideoWriter* video = nullptr;  ///< MP4 of the rendered frames
  LiveFeed* live = nullptr;      ///< live view fed by the sim thread
};

/// Samples the servo may queue between two frames before they are dropped (8 s at 1 kHz).
inline constexpr std::size_t kSessionSampleQueue = 8192;

/// A change of the controls a session started again under: after frame `frame` (scene time t_s). Plain data.
struct ControlChange {
  int64_t frame = 0;
  double t_s = 0.0;
  Controls controls{};
};

/// One run's servo and frame stage, connected. Not copyable or movable (the parts point at each other).
/// A person's change of the controls (core/controls.h, carried by the servo's samples) starts the model again: after
/// the frame that took the first sample under it, the frame stage is built anew from the scene the controls make
/// (core/scene_controls.h), at rest, its figures carried over; the servo already runs under them and feels no surface
/// until the new stage's first patch. A replay changes it after the same frame.
/// Thread: construct, run_lockstep, frame and finish on the sim thread; servo() ticks on the servo thread.
class Session {
 public:
  /// The servo as the scene asks for it on `device` at scene.rates.servo_hz (servo_params_for: coupling capped by
  /// the device's and the passivity limits); the lattice stepped 1 / scene.rates.frame_hz per frame. Every part
  /// reads scene.rates. scene, model and device must outlive the session.
  Session(const Scene& scene, const Model& model, Device* device, const SessionOutputs& outputs = {});
  /// As above with explicit servo parameters (a benchmark comparing force models, a test without the scene's caps).
  Session(const Scene& scene, const Model& model, Device* device, const ServoParams& params,
          const SessionOutputs& outputs = {});
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// Runs the session on a virtual clock for duration_s (see palpate::run_lockstep): every frame blocks on the
  /// writers, so the run is reproducible bit for bit. A device that replays a recorded run with its schedule
  /// (Device::schedule) is run in that run's order instead (palpate::run_scheduled), whatever duration_s. after_frame(index, t_s) is called after each frame and
  /// after_tick(index, t_s) after each servo tick; the servo's compute time goes to lockstep_compute().
  /// Ends with finish().
  template <class AfterFrame, class AfterTick>
  void run_lockstep(double duration_s, AfterFrame&& after_frame, AfterTick&& after_tick);
  /// As above with a per-frame hook only.
  template <class AfterFrame>
  void run_lockstep(double duration_s, AfterFrame&& after_frame) {
    run_lockstep(duration_s, std::forward<AfterFrame>(after_frame), [](int64_t, double) {});
  }

  /// One servo tick at scene time t_s (lockstep drivers; a realtime driver gives servo() to a ServoRunner).
  void tick(int64_t index, double t_s) noexcept { servo_.tick(index, t_s); }
  /// Frame `index` at its scene time index / frame_hz; block_on_writer: wait for the PNG writer and the video
  /// (lockstep) instead of dropping the frame (realtime).
  void frame(int64_t index, bool block_on_writer) { frame_at(index, frame_time_s(index), block_on_writer); }
  /// Frame `index` at scene time t_s, taking the servo's samples up to tick drain_to_tick (FrameStage::frame); then,
  /// when those samples brought new controls, the stage starts again under them.
  void frame_at(int64_t index, double t_s, bool block_on_writer, int64_t drain_to_tick = INT64_MAX);
  /// Draws the current state once, written nowhere (FrameStage::warm_up): before a realtime clock starts.
  void warm_up() { stage_->warm_up(); }
  /// The frame stage keeps lattice.budget_ms by `clock` (FrameStage::use_budget), also after a restart.
  void use_budget(BudgetClock* clock);
  /// Realtime: every frame's step has a deadline (FrameStage::keep_deadlines), also after a restart.
  void keep_deadlines();
  /// The controls' changes the session started again under, in order (empty: the scene's own throughout).
  const std::vector<ControlChange>& control_changes() const { return changes_; }
  /// The scene the stage runs now: the session's, or the one the last change of the controls made.
  const Scene& current_scene() const { return scenes_.empty() ? scene_ : scenes_.back(); }
  /// Scene time of frame `index`.
  double frame_time_s(int64_t index) const { return rates().frame_time_s(index); }
  /// Drains and logs the samples left after the last frame (the servo must have stopped).
  void finish() { stage_->drain_remaining(); }

  /// The run's rates (the scene's).
  const Rates& rates() const { return scene_.rates; }
  const ServoParams& servo_params() const { return params_; }
  Servo& servo() { return servo_; }
  const Servo& servo() const { return servo_; }
  FrameStage& stage() { return *stage_; }
  const FrameStage& stage() const { return *stage_; }
  SpscQueue<HapticSample>& samples() { return samples_; }
  TripleBuffer<LocalModel>& local_model() { return *local_model_; }
  /// Lockstep: time inside each servo tick (1 us buckets, as a ServoRunner's compute figure).
  const LatencyHistogram& lockstep_compute() const { return compute_; }

 private:
  // the stage built anew under `c` after frame `frame`
  void restart(Controls c, int64_t frame, double t_s);
  const Scene& scene_;
  const Model& model_;
  Device* device_;
  SessionOutputs outputs_;
  ServoParams params_;
  SpscQueue<HapticSample> samples_;
  std::unique_ptr<TripleBuffer<LocalModel>> local_model_;  // large: on the heap
  Servo servo_;
  std::optional<FrameStage> stage_;
  LatencyHistogram compute_;
  std::deque<Scene> scenes_;          // the scenes the controls made (a stage keeps a reference to its own)
  std::vector<ControlChange> changes_;
  Controls applied_;                  // the controls the stage runs under
  BudgetClock* budget_clock_ = nullptr;
  bool deadlines_ = false;
};

template <class AfterFrame, class AfterTick>
void Session::run_lockstep(double duration_s, AfterFrame&& after_frame, AfterTick&& after_tick) {
  auto on_tick = [&](int64_t i, double t) {
    const int64_t c0 = monotonic_ns();
    servo_.tick(i, t);
    compute_.add(monotonic_ns() - c0);
    after_tick(i, t);
  };
  if (const RunSchedule* schedule = device_->schedule()) {
    // a replayed run: its ticks and frames in the order they ran (duration_s is the log's)
    palpate::run_scheduled(
        rates(), *schedule,
        [&](int64_t f, double t, int64_t drain_to_tick) {
          frame_at(f, t, true, drain_to_tick);
          after_frame(f, t);
        },
        on_tick);
  } else {
    palpate::run_lockstep(
        rates(), duration_s,
        [&](int64_t f, double t) {
          frame_at(f, t, true);
          after_frame(f, t);
        },
        on_tick);
  }
  finish();
}

}  // namespace palpate
