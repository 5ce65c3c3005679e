#include "render/video_writer.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <new>
#include <string>

namespace palpate {

VideoWriter::VideoWriter(std::unique_ptr<VideoEncoder> encoder, int width, int height, int queue_frames)
    : encoder_(std::move(encoder)),
      frame_bytes_(static_cast<std::size_t>(std::max(width, 1)) * static_cast<std::size_t>(std::max(height, 1)) * 4),
      jobs_(static_cast<std::size_t>(std::max(queue_frames, 1)), frame_bytes_) {
  encode_ms_.reserve(1024);
  thread_ = std::thread([this] { run(); });
}

VideoWriter::~VideoWriter() {
  jobs_.close();
  if (thread_.joinable()) thread_.join();
}

bool VideoWriter::submit(int64_t index, const uint8_t* rgba, bool block) {
  if (rgba == nullptr) return false;
  uint8_t* copy = failed_.load(std::memory_order_relaxed) ? nullptr : jobs_.acquire(block);
  if (copy != nullptr && failed_.load(std::memory_order_relaxed)) {
    jobs_.release(copy);  // the encoder failed while this call waited
    copy = nullptr;
  }
  if (copy == nullptr) {
    frames_dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  // the copy is made outside the lock: the encoder thread never touches a buffer on the free list
  std::memcpy(copy, rgba, frame_bytes_);
  if (!jobs_.push(Job{index, copy})) {
    frames_dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  return true;
}

Status VideoWriter::finish() {
  if (!finished_) {
    finished_ = true;
    jobs_.close();
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
  Job job;
  // finish() still drains what was queued
  while (jobs_.pop(&job)) {
    if (!failed_.load(std::memory_order_relaxed)) {
      const auto t0 = std::chrono::steady_clock::now();
      // out of memory in the encoder fails the video (said in the summary), never the recording
      Status st = Ok{};
      try {
        st = encoder_->encode(job.buffer, job.index);
      } catch (const std::bad_alloc&) {
        st = make_error("video: out of memory while encoding frame ", std::to_string(job.index));
      }
      if (st) {
        // room is reserved for the first frames; past them a failed growth only loses the timing
        try {
          encode_ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        } catch (const std::bad_alloc&) {
        }
        frames_encoded_.fetch_add(1, std::memory_order_relaxed);
      } else {
        // later frames are dropped and counted; finish() reports this error
        error_ = std::move(st);
        failed_.store(true, std::memory_order_relaxed);
      }
    } else {
      frames_dropped_.fetch_add(1, std::memory_order_relaxed);
    }
    jobs_.release(job.buffer);
  }
}

}  // namespace palpate
