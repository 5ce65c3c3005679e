#pragma once
/// VideoWriter: a background thread that encodes rendered frames into an MP4 through a VideoEncoder.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/buffer_job_queue.h"
#include "core/result.h"
#include "render/video_encoder.h"

namespace palpate {

/// An encoder thread fed through a fixed pool of frame copies (allocated in the constructor only); not copyable.
/// submit() copies the caller's RGBA frame, so the caller may reuse its buffer as soon as submit returns.
/// Thread: submit/finish from one producer thread; the counters from any thread.
class VideoWriter {
 public:
  /// Takes the opened encoder, allocates queue_frames (at least 1) copies of width*height*4 bytes and starts
  /// the encoder thread.
  VideoWriter(std::unique_ptr<VideoEncoder> encoder, int width, int height, int queue_frames);
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;
  /// Joins the thread; an unfinished video's temporary file is removed.
  ~VideoWriter();

  /// Queues a copy of frame `index` (scene frame; a gap holds the previous frame). block=true waits for a free
  /// copy (lockstep); block=false drops the frame when the encoder is behind and counts it (realtime). False when
  /// dropped, after finish() or after an encoder error.
  bool submit(int64_t index, const uint8_t* rgba, bool block);
  /// Encodes everything queued, joins the thread and finishes the file; the first error of the run if any.
  Status finish();

  /// Frames encoded so far.
  int64_t frames_encoded() const { return frames_encoded_.load(std::memory_order_relaxed); }
  /// Frames dropped because the queue was full (realtime) or the encoder had failed.
  int64_t frames_dropped() const { return frames_dropped_.load(std::memory_order_relaxed); }
  /// Milliseconds to convert and encode each frame, in order; valid after finish().
  const std::vector<double>& encode_ms() const { return encode_ms_; }
  /// Milliseconds to flush the encoder and write the index at finish(); valid after finish().
  double finish_ms() const { return finish_ms_; }
  /// The encoder (name, path, bytes after finish()).
  const VideoEncoder& encoder() const { return *encoder_; }

 private:
  struct Job {
    int64_t index = 0;
    uint8_t* buffer = nullptr;
  };

  void run();

  std::unique_ptr<VideoEncoder> encoder_;
  const std::size_t frame_bytes_;
  BufferJobQueue<Job> jobs_;             // frame copies (queue_frames x w*h*4) and the frames queued on them
  Status error_ = Ok{};                  // first encoder error (encoder thread; read after join)
  std::atomic<bool> failed_{false};

  std::atomic<int64_t> frames_encoded_{0};
  std::atomic<int64_t> frames_dropped_{0};
  std::vector<double> encode_ms_;  // written by the encoder thread, read after join
  double finish_ms_ = 0.0;
  bool finished_ = false;          // producer side only
  std::thread thread_;
};

}  // namespace palpate
