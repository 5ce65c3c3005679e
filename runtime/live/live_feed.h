#pragma once
/// LiveFeed: what a recording shows while it runs. The sim thread publishes the latest rendered frame, one plot
/// point per frame and the session's figures; the live server's threads read them. The sim thread never waits
/// for a reader: pixels are copied only when a client asked for frames recently and only when no reader holds
/// the slot at that moment; points go through a lock-free queue, figures through a triple buffer.

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "core/spsc_queue.h"
#include "core/triple_buffer.h"
#include "haptics/servo/haptic_sample.h"
#include "haptics/servo/latency_histogram.h"

namespace palpate {

/// One frame's figures for the live plots. Plain data.
struct LivePoint {
  int64_t frame = 0;         ///< scene frame index
  double t_s = 0.0;          ///< scene time of the frame
  float force_N = 0.0f;      ///< largest device force magnitude among the frame's servo samples
  uint8_t contact = 0;       ///< ContactState of the frame's newest sample
  float wake_max_us = 0.0f;  ///< largest servo wake latency among the frame's samples (0 on a virtual clock)
  float frame_ms = 0.0f;     ///< the frame's work: drain, step, deform, render
  float late_ms = 0.0f;      ///< realtime: how late the frame started after its deadline
};

/// The session's running figures. Plain data.
struct LiveFigures {
  int64_t frames = 0;           ///< frames processed
  int64_t frames_written = 0;   ///< PNG files written
  int64_t frames_dropped = 0;   ///< realtime: frames not rendered because the writer was full
  int64_t frames_late = 0;      ///< realtime: frames skipped a whole period late
  int64_t servo_ticks = 0;      ///< servo samples seen
  int64_t overruns = 0;         ///< servo periods missed
  double servo_p50_us = 0.0;    ///< servo wake latency percentiles
  double servo_p99_us = 0.0;
  double t_s = 0.0;             ///< scene time reached
  double max_force_N = 0.0;     ///< largest device force so far
  bool finished = false;        ///< the recording is over; these are its final figures (as in summary.json)
};

/// Shared between one sim thread (the publishing calls) and the server's threads (the reading calls, which
/// serialize among themselves). Not copyable.
class LiveFeed {
 public:
  /// Frames are width x height RGBA, rows top-down. scene/mode are shown on the page.
  LiveFeed(int width, int height, std::string scene, std::string mode);
  LiveFeed(const LiveFeed&) = delete;
  LiveFeed& operator=(const LiveFeed&) = delete;

  // ---- sim thread: never blocks, never allocates ----
  /// A servo sample drained this frame.
  void add_sample(const HapticSample& s) noexcept;
  /// How late the coming frame started (realtime loop).
  void set_frame_late_ns(int64_t ns) noexcept { late_ns_ = ns; }
  /// The realtime loop skipped a frame that started a whole period late.
  void frame_skipped() noexcept { ++frames_late_; }
  /// A rendered frame (width*height*4 bytes); copied only when a client wants frames and the slot is free.
  void offer_frame(int64_t index, const uint8_t* rgba) noexcept;
  /// Ends frame `index`: pushes its plot point and publishes the running figures.
  void end_frame(int64_t index, double t_s, double frame_ms, int64_t frames, int64_t frames_written,
                 int64_t frames_dropped) noexcept;
  /// The recording is over: its final figures (those summary.json holds).
  void finish(const LiveFigures& final_figures) noexcept;

  // ---- readers (server threads) ----
  int width() const { return width_; }
  int height() const { return height_; }
  const std::string& scene() const { return scene_; }
  const std::string& mode() const { return mode_; }
  /// Where the recording's outputs go (shown on the page when the run ends); set before the server starts.
  void set_out_dir(std::string dir) { out_dir_ = std::move(dir); }
  const std::string& out_dir() const { return out_dir_; }
  /// Scene index of the newest frame copied into the slot, -1 before the first.
  int64_t frame_index() const noexcept { return slot_index_.load(std::memory_order_acquire); }
  /// Clients want frames until monotonic time until_ns (the sim thread copies none otherwise).
  void want_frames_until(int64_t until_ns) noexcept;
  /// Copies every frame, asked for or not (so the last one is there for a client that comes after the run).
  void keep_frames() noexcept { want_frames_until(INT64_MAX); }
  /// Copies the newest frame into *rgba when it is newer than `after`; returns its index, or -1 when none is.
  int64_t copy_frame(int64_t after, std::vector<uint8_t>* rgba);
  /// Moves the points published since the last call onto *out. Thread: one reader at a time.
  void take_points(std::vector<LivePoint>* out);
  /// The newest figures. Thread: one reader at a time.
  LiveFigures figures();
  /// Points lost because no reader took them in time (the queue was full).
  int64_t points_dropped() const noexcept { return points_dropped_.load(std::memory_order_relaxed); }

 private:
  const int width_, height_;
  const std::string scene_, mode_;
  std::string out_dir_;

  // frame slot: the sim thread writes under try_lock, a reader copies under lock
  std::mutex slot_mutex_;
  std::vector<uint8_t> slot_;
  std::atomic<int64_t> slot_index_{-1};
  std::atomic<int64_t> want_until_ns_{0};

  SpscQueue<LivePoint> points_;
  std::atomic<int64_t> points_dropped_{0};
  TripleBuffer<LiveFigures> figures_;
  std::atomic<bool> finished_{false};  // after finish(), end_frame publishes nothing more

  // sim-thread accumulators
  LatencyHistogram wake_;       // every sample's wake latency
  int64_t ticks_seen_ = 0;
  int64_t last_tick_ = -1;
  int64_t overruns_ = 0;        // gaps in the tick numbers
  float frame_force_N_ = 0.0f;
  float frame_wake_us_ = 0.0f;
  uint8_t frame_contact_ = 0;
  double max_force_N_ = 0.0;
  int64_t late_ns_ = 0;
  int64_t frames_late_ = 0;
};

}  // namespace palpate
