#include "render/png_writer.h"

#include <algorithm>
#include <chrono>
#include <new>
#include <cstdio>
#include <string_view>
#include <utility>

#include "core/atomic_file.h"
#include "render/png_io.h"

namespace palpate {

namespace {
// a frame that ran out of memory: the start of its error, before the frame's name (no allocation to make it)
constexpr const char* kOutOfMemoryPrefix = "png: out of memory while encoding ";
}  // namespace

PngWriter::PngWriter(std::string dir, int width, int height, int pool_size, const PngWriterConfig& config)
    : dir_(std::move(dir)),
      width_(std::max(width, 1)),
      height_(std::max(height, 1)),
      config_(config),
      jobs_(static_cast<std::size_t>(std::max(pool_size, 1)),
            static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4) {
  encoded_.resize(2 * static_cast<std::size_t>(std::max(pool_size, 1)));
  png_ms_.reserve(1024);
  // a thread the system refuses (std::system_error: too many threads, or no memory for a stack) ends the
  // construction with that error after the threads already running are stopped and joined, never with a running
  // thread destroyed (std::terminate)
  try {
    for (int i = 0; i < std::max(config_.threads, 1); ++i) threads_.emplace_back([this] { run(); });
    committer_ = std::thread([this] { commit_run(); });
  } catch (...) {
    finish();
    throw;
  }
}

PngWriter::~PngWriter() { finish(); }

uint8_t* PngWriter::acquire(bool block) { return jobs_.acquire(block); }

void PngWriter::submit(int index, uint8_t* buffer) {
  if (buffer == nullptr) return;
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  if (!jobs_.owns(buffer)) {
    record_error("png '" + dir_ + "/" + name + "': buffer was not acquired from this writer");
    return;
  }
  if (jobs_.push(Job{index, buffer, next_seq_})) {
    ++next_seq_;
    return;
  }
  record_error("png '" + dir_ + "/" + name + "': submitted after finish()");
}

void PngWriter::finish() {
  if (finished_) return;
  finished_ = true;
  jobs_.close();
  for (auto& t : threads_)
    if (t.joinable()) t.join();
  // every frame an encoder took is with the committer now
  {
    std::lock_guard<std::mutex> lock(commit_mutex_);
    encoders_done_ = true;
  }
  commit_ready_.notify_all();
  if (committer_.joinable()) committer_.join();
}

std::string PngWriter::first_error() const {
  std::lock_guard<std::mutex> lock(error_mutex_);
  return first_error_;
}

void PngWriter::record_error(const std::string& message) {
  write_errors_.fetch_add(1, std::memory_order_relaxed);
  std::lock_guard<std::mutex> lock(error_mutex_);
  if (first_error_.empty()) first_error_ = message;
}

void PngWriter::run() {
  PngEncoder encoder(config_.codec);  // this thread's compressor and buffers
  encoder.set_keep_alpha(config_.keep_alpha);
  char name[32];
  Job job;
  // finish() still drains what was queued
  while (jobs_.pop(&job)) {
    std::snprintf(name, sizeof name, "frame_%05d.png", job.index);
    const auto start = std::chrono::steady_clock::now();
    Encoded done;
    bool released = false;
    // out of memory here fails this frame like a full disk would (named, the frames before it kept), never the
    // process: the frame and those after it are counted as not written and the recording ends with its summary
    try {
      const std::string path = dir_ + "/" + name;
      // after a frame failed (a full disk) the rest are not encoded: none of them could follow it
      Status written = failed_.load(std::memory_order_acquire)
                           ? Status(make_error("png '", path, "': not written after an earlier frame failed"))
                           : encoder.encode(width_, height_, job.buffer, path);
      // the pixels are in the encoder's output now: the buffer goes back to the producer before the disk work
      jobs_.release(job.buffer);
      released = true;
      if (written.ok()) {
        Result<AtomicFile> file = AtomicFile::open(path, "png");
        if (file) {
          const auto bytes = encoder.bytes();
          file.value().write(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
          done.file = std::move(file).value();
        } else {
          done.error = file.error().message;
        }
      } else {
        done.error = written.error().message;
      }
    } catch (const std::bad_alloc&) {
      if (!released) jobs_.release(job.buffer);
      done = Encoded{};
      done.error = kOutOfMemoryPrefix;
      done.error += name;
    }
    done.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    done.ready = true;
    // to the committer; at most encoded_.size() frames wait there (the earliest always has room)
    {
      std::unique_lock<std::mutex> lock(commit_mutex_);
      const auto slots = static_cast<int64_t>(encoded_.size());
      commit_space_.wait(lock, [&] { return job.seq - next_rename_ < slots; });
      encoded_[static_cast<std::size_t>(job.seq % slots)] = std::move(done);
      ++delivered_;
    }
    commit_ready_.notify_one();
  }
}

void PngWriter::commit_run() {
  const auto slots = static_cast<int64_t>(encoded_.size());
  for (;;) {
    Encoded frame;
    {
      std::unique_lock<std::mutex> lock(commit_mutex_);
      Encoded* next = &encoded_[static_cast<std::size_t>(next_rename_ % slots)];
      commit_ready_.wait(lock, [&] { return next->ready || (encoders_done_ && next_rename_ == delivered_); });
      if (!next->ready) return;
      frame = std::move(*next);
      next->ready = false;
    }
    // fsync, then the rename: a frame appears only complete and after every frame before it
    Status written = Ok{};
    if (!frame.error.empty()) {
      written = make_error(frame.error);
    } else if (failed_.load(std::memory_order_acquire)) {
      // a frame after a failed one is never renamed, so the folder keeps a gapless prefix
      written = make_error("png '", frame.file.path(), "': not written after an earlier frame failed");
    } else {
      written = frame.file.sync();
      if (written.ok()) written = frame.file.commit();
    }
    if (written.ok()) {
      // png_ms_ has room reserved for the first frames; past them a failed growth only loses the timing
      try {
        png_ms_.push_back(frame.ms);
      } catch (const std::bad_alloc&) {
      }
      frames_written_.fetch_add(1, std::memory_order_relaxed);
    } else {
      frame.file.discard();
      failed_.store(true, std::memory_order_release);
      record_error(written.error().message);
    }
    {
      std::lock_guard<std::mutex> lock(commit_mutex_);
      ++next_rename_;
    }
    commit_space_.notify_all();
  }
}

}  // namespace palpate
