#pragma once
/// FrameOutputs: where a frame's picture goes. The renderer draws it with the frame's look (ViewStyle: colours,
/// arrow, legend, trace, floor), then the same pixels go to the PNG writer, the video and the live view; the render
/// figures go into FrameStats. A frame whose PNG buffer is not free (realtime) is dropped and counted. Thread: the
/// sim thread only.

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <vector>

#include "core/scene.h"
#include "render/png_writer.h"
#include "render/renderer.h"
#include "render/video_writer.h"
#include "runtime/live/live_feed.h"
#include "runtime/session/frame_stats.h"
#include "runtime/session/model.h"
#include "runtime/session/view_style.h"
#include "sim/solvers/frame_budget.h"

namespace palpate {

class FrameOutputs {
 public:
  /// renderer / writer may be null (nothing drawn); all pointers must outlive it.
  FrameOutputs(const Scene& scene, const Model& model, Renderer* renderer, PngWriter* writer, FrameStats* stats)
      : renderer_(renderer), writer_(writer), stats_(stats), style_(scene, model) {}
  void set_video(VideoWriter* video) { video_ = video; }
  void set_live(LiveFeed* live) { live_ = live; }
  LiveFeed* live() const { return live_; }
  Renderer* renderer() const { return renderer_; }
  /// The frames' look; the view a frame is drawn with takes it (ViewStyle::apply).
  const ViewStyle& style() const { return style_; }
  /// A servo tick sent force_N to the hand: the trace takes the largest of a drawn frame's ticks.
  void note_tick(double force_N) { peak_N_ = std::max(peak_N_, force_N); }
  /// A frame is drawn: a PNG buffer for it (block: wait for a free one, as lockstep does), else null and the frame
  /// counted dropped; null too when nothing is drawn. The frame's render time starts here.
  uint8_t* acquire(bool block);
  /// Draws `view` into buf (acquire()'s) as scene frame `index` and hands the pixels on; latest_force_N: the trace's
  /// value when no tick came since the last frame.
  void draw(int64_t index, bool block, uint8_t* buf, const FrameView& view, double latest_force_N);
  /// Draws `view` once and writes it nowhere (a realtime run's warm-up: the GL driver's first draw compiles).
  void warm(const FrameView& view);
  /// PNG files written so far.
  int64_t frames_written() const { return writer_ ? writer_->frames_written() : 0; }

 private:
  Renderer* renderer_;
  PngWriter* writer_;
  VideoWriter* video_ = nullptr;
  LiveFeed* live_ = nullptr;
  FrameStats* stats_;
  ViewStyle style_;
  ThreadCpuClock cpu_clock_;       // the render's CPU time
  double peak_N_ = -1.0;           // the largest force a tick sent since the last frame drawn (-1: no tick)
  std::chrono::steady_clock::time_point t0_;  // when the frame being drawn was acquired, on both clocks
  double c0_ = 0.0;
  int64_t builds_ = 0;             // the renderer's layer builds then
  std::vector<uint8_t> warm_rgba_; // warm()'s frame, never written (w * h * 4)
};

}  // namespace palpate
