#include "render/png_writer.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <utility>

#include "render/png_io.h"

namespace palpate {

PngWriter::PngWriter(std::string dir, int width, int height, int pool_size)
    : dir_(std::move(dir)), width_(std::max(width, 1)), height_(std::max(height, 1)) {
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
  thread_ = std::thread([this] { run(); });
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
      queue_[(queue_head_ + queue_size_) % queue_.size()] = Job{index, buffer};
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
  job_ready_.notify_one();
  buffer_free_.notify_all();
  if (thread_.joinable()) thread_.join();
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
    const auto start = std::chrono::steady_clock::now();
    Status written = write_png(dir_ + "/" + name, width_, height_, job.buffer);
    const std::chrono::duration<double, std::milli> elapsed = std::chrono::steady_clock::now() - start;
    if (written.ok()) {
      png_ms_.push_back(elapsed.count());
      frames_written_.fetch_add(1, std::memory_order_relaxed);
    } else {
      record_error(written.error().message);
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      free_.push_back(job.buffer);
    }
    buffer_free_.notify_one();
  }
}

}  // namespace palpate
