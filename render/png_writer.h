#pragma once
/// PngWriter: background threads that write rendered frames as numbered PNG files.

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/atomic_file.h"
#include "core/buffer_job_queue.h"
#include "render/png_io.h"

namespace palpate {

/// How a PngWriter encodes.
struct PngWriterConfig {
  int threads = 1;                        ///< encoder threads (at least 1)
  PngCodec codec = PngCodec::kLibdeflate; ///< compressor of the image data
  bool keep_alpha = false;                ///< RGBA even for opaque frames (the format before RGB frames)
};

/// Encoder threads with a fixed pool of frame buffers (allocated in the constructor only); not copyable.
/// Frames are written as <dir>/frame_%05d.png; the directory must exist. With several threads, frames are
/// encoded and written to a temporary in parallel, each thread taking the next frame queued; one more thread
/// fsyncs the temporaries and renames them to their final names strictly in the order submitted, so the
/// encoders never wait for the disk and the folder only ever holds a complete, gapless prefix of the sequence.
/// Once a frame fails (a full disk: the error names it with errno's text), no later frame is renamed, nor encoded
/// if it has not started: each counts as a write error and first_error() stays the failed frame's.
/// A buffer is free again as soon as its frame is encoded.
/// Thread: acquire/submit/finish from one producer thread; the counters from any thread.
class PngWriter {
 public:
  /// Allocates pool_size (at least 1) buffers of width*height*4 bytes and starts config.threads encoder threads.
  PngWriter(std::string dir, int width, int height, int pool_size, const PngWriterConfig& config = {});
  PngWriter(const PngWriter&) = delete;
  PngWriter& operator=(const PngWriter&) = delete;
  /// Finishes (drains the queue) and joins.
  ~PngWriter();

  /// A free buffer (w*h*4 bytes) or nullptr when all are in flight; block=true waits for one
  /// (nullptr after finish()).
  uint8_t* acquire(bool block);
  /// Queues an acquired buffer for writing as frame `index`; after finish() the frame is dropped and counted
  /// as a write error.
  void submit(int index, uint8_t* buffer);
  /// Writes everything queued and joins the threads; idempotent.
  void finish();

  /// Frames written successfully so far.
  int frames_written() const { return frames_written_.load(std::memory_order_relaxed); }
  /// Frames that failed to write (or were submitted after finish()).
  int write_errors() const { return write_errors_.load(std::memory_order_relaxed); }
  /// The first error message, empty when none.
  std::string first_error() const;
  /// Milliseconds spent encoding and writing each written frame to its temporary (on its encoder thread; the
  /// fsync and rename after it are not counted), in order; valid after finish().
  const std::vector<double>& png_ms() const { return png_ms_; }

 private:
  struct Job {
    int index = 0;
    uint8_t* buffer = nullptr;
    int64_t seq = 0;  // submission order
  };

  // an encoded frame waiting for its turn to be synced and renamed
  struct Encoded {
    bool ready = false;
    AtomicFile file;    // written, not yet synced (when error is empty)
    std::string error;  // encoding or opening failed
    double ms = 0.0;    // encode + write
  };

  void run();
  void commit_run();
  void record_error(const std::string& message);

  const std::string dir_;
  const int width_;
  const int height_;
  const PngWriterConfig config_;
  BufferJobQueue<Job> jobs_;             // frame buffers (pool_size x w*h*4) and the frames queued on them

  mutable std::mutex error_mutex_;
  std::string first_error_;

  int64_t next_seq_ = 0;                 // seq of the next job submitted

  std::mutex commit_mutex_;
  std::condition_variable commit_ready_;  // committer waits: the next frame encoded, or the encoders gone
  std::condition_variable commit_space_;  // encoders wait: a free slot in encoded_
  std::vector<Encoded> encoded_;          // ring by seq (capacity 2 x pool_size): frames ahead of the renames
  int64_t next_rename_ = 0;               // seq whose turn it is (committer)
  int64_t delivered_ = 0;                 // frames handed to the committer
  bool encoders_done_ = false;

  std::atomic<int> frames_written_{0};
  std::atomic<int> write_errors_{0};
  std::atomic<bool> failed_{false};  // a frame failed: later ones are dropped (set by the committer)
  std::vector<double> png_ms_;  // written in rename order by the committer, read after join
  bool finished_ = false;       // producer side only
  std::vector<std::thread> threads_;
  std::thread committer_;
};

}  // namespace palpate
