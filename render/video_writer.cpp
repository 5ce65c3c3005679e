#include "render/video_writer.h"

#include <algorithm>
#include <chrono>
#include <cstring>

namespace palpate {

VideoWriter::VideoWriter(std::unique_ptr<VideoEncoder> encoder, int width, int height, int queue_frames)
    : encoder_(std::move(encoder)),
      frame_bytes_(static_cast<std::size_t>(std::max(width, 1)) * static_cast<std::size_t>(std::max(height, 1)) * 4) {
  const auto n = static_cast<std::size_t>(std::max(queue_frames, 1));
  pool_.resize(n);
  free_.reserve(n);
  for (auto& b : pool_) {
    b.assign(frame_bytes_, 0);
    free_.push_back(b.data());
  }
  queue_.resize(n);
  encode_ms_.reserve(1024);
  thread_ = std::thread([this] { run(); });
}

VideoWriter::~VideoWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  job_ready_.notify_one();
  buffer_free_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool VideoWriter::submit(int64_t index, const uint8_t* rgba, bool block) {
  if (rgba == nullptr) return false;
  uint8_t* copy = nullptr;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (block) buffer_free_.wait(lock, [this] { return !free_.empty() || stopping_; });
    if (!free_.empty() && !stopping_ && !failed_.load(std::memory_order_relaxed)) {
      copy = free_.back();
      free_.pop_back();
    }
  }
  if (copy == nullptr) {
    frames_dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  // the copy is made outside the lock: the encoder thread never touches a buffer on the free list
  std::memcpy(copy, rgba, frame_bytes_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // at most queue_frames copies are out, so the ring never overflows
    queue_[(queue_head_ + queue_size_) % queue_.size()] = Job{index, copy};
    ++queue_size_;
  }
  job_ready_.notify_one();
  return true;
}

Status VideoWriter::finish() {
  if (!finished_) {
    finished_ = true;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    job_ready_.notify_one();
    buffer_free_.notify_all();
    if (thread_.joinable()) thread_.join();
    if (error_) {
      const auto t0 = std::chrono::steady_clock::now();
      error_ = encoder_->finish();
      finish_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
  }
  return error_;
}

void VideoWriter::run() {
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
    if (!failed_.load(std::memory_order_relaxed)) {
      const auto t0 = std::chrono::steady_clock::now();
      Status st = encoder_->encode(job.buffer, job.index);
      if (st) {
        encode_ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        frames_encoded_.fetch_add(1, std::memory_order_relaxed);
      } else {
        // later frames are dropped and counted; finish() reports this error
        error_ = std::move(st);
        failed_.store(true, std::memory_order_relaxed);
      }
    } else {
      frames_dropped_.fetch_add(1, std::memory_order_relaxed);
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      free_.push_back(job.buffer);
    }
    buffer_free_.notify_one();
  }
}

}  // namespace palpate
