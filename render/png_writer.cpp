#include "render/png_writer.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string_view>
#include <utility>

#include "core/atomic_file.h"
#include "render/png_io.h"

namespace palpate {

PngWriter::PngWriter(std::string dir, int width, int height, int pool_size, const PngWriterConfig& config)
    : dir_(std::move(dir)), width_(std::max(width, 1)), height_(std::max(height, 1)), config_(config) {
  const auto n = static_cast<std::size_t>(std::max(pool_size, 1));
  const std::size_t bytes = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 4;
  pool_.resize(n);
  free_.reserve(n);
  for (auto& buffer : pool_) {
    buffer.assign(bytes, 0);
    free_.push_back(buffer.data());
  }
  queue_.resize(n);
  png_ms_.reserve(1024);
  for (int i = 0; i < std::max(config_.threads, 1); ++i) threads_.emplace_back([this] { run(); });
}

PngWriter::~PngWriter() { finish(); }

uint8_t* PngWriter::acquire(bool block) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (block) buffer_free_.wait(lock, [this] { return !free_.empty() || stopping_; });
  if (free_.empty() || stopping_) return nullptr;
  uint8_t* buffer = free_.back();
  free_.pop_back();
  return buffer;
}

void PngWriter::submit(int index, uint8_t* buffer) {
  if (buffer == nullptr) return;
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  const bool from_pool =
      std::any_of(pool_.begin(), pool_.end(), [buffer](const auto& b) { return b.data() == buffer; });
  if (!from_pool) {
    record_error("png '" + dir_ + "/" + name + "': buffer was not acquired from this writer");
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!stopping_) {
      // at most pool_size buffers are out, so the ring never overflows
      queue_[(queue_head_ + queue_size_) % queue_.size()] = Job{index, buffer, next_seq_++};
      ++queue_size_;
      job_ready_.notify_one();
      return;
    }
    free_.push_back(buffer);
  }
  record_error("png '" + dir_ + "/" + name + "': submitted after finish()");
}

void PngWriter::finish() {
  if (finished_) return;
  finished_ = true;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  job_ready_.notify_all();
  buffer_free_.notify_all();
  for (auto& t : threads_)
    if (t.joinable()) t.join();
}

std::string PngWriter::first_error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return first_error_;
}

void PngWriter::record_error(const std::string& message) {
  write_errors_.fetch_add(1, std::memory_order_relaxed);
  std::lock_guard<std::mutex> lock(mutex_);
  if (first_error_.empty()) first_error_ = message;
}

void PngWriter::run() {
  PngEncoder encoder(config_.codec);  // this thread's compressor and buffers
  encoder.set_keep_alpha(config_.keep_alpha);
  char name[32];
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      job_ready_.wait(lock, [this] { return queue_size_ > 0 || stopping_; });
      // stopping still drains what was queued
      if (queue_size_ == 0) return;
      job = queue_[queue_head_];
      queue_head_ = (queue_head_ + 1) % queue_.size();
      --queue_size_;
    }
    std::snprintf(name, sizeof name, "frame_%05d.png", job.index);
    const std::string path = dir_ + "/" + name;
    const auto start = std::chrono::steady_clock::now();
    // after a frame failed (a full disk) the rest are not encoded: none of them could follow it
    Status written = failed_.load(std::memory_order_acquire)
                         ? Status(make_error("png '", path, "': not written after an earlier frame failed"))
                         : encoder.encode(width_, height_, job.buffer, path);
    // the pixels are in the encoder's output now: the buffer goes back to the producer before the disk work
    {
      std::lock_guard<std::mutex> lock(mutex_);
      free_.push_back(job.buffer);
    }
    buffer_free_.notify_one();
    Result<AtomicFile> file = written.ok() ? AtomicFile::open(path, "png") : Result<AtomicFile>(written.error());
    if (file) {
      const auto& bytes = encoder.bytes();
      file.value().write(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
      written = file.value().sync();
    } else {
      written = file.error();
    }
    const std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
    // renames in submission order: a frame appears only after every frame before it
    std::unique_lock<std::mutex> turn(rename_mutex_);
    rename_turn_.wait(turn, [&] { return next_rename_ == job.seq; });
    // a frame after a failed one is never renamed, so the folder keeps a gapless prefix
    if (written.ok() && failed_.load(std::memory_order_acquire))
      written = make_error("png '", path, "': not written after an earlier frame failed");
    if (written.ok()) written = file.value().commit();
    if (written.ok()) {
      png_ms_.push_back(elapsed.count());
      frames_written_.fetch_add(1, std::memory_order_relaxed);
    } else {
      if (file) file.value().discard();
      failed_.store(true, std::memory_order_release);
      record_error(written.error().message);
    }
    ++next_rename_;
    turn.unlock();
    rename_turn_.notify_all();
  }
}

}  // namespace palpate
