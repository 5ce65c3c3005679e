#pragma once
/// BufferJobQueue: a fixed pool of byte buffers and a bounded FIFO of jobs on them, between one producer and one
/// or more worker threads — the mechanism of the PNG frame writer and of the video writer. Buffers and the ring
/// are allocated in the constructor only; at most `buffers` jobs are ever queued (each holds a buffer), so the ring
/// never overflows. Not copyable or movable.
/// Thread: acquire/push/close from the producer; pop/release from the workers; owns() from any thread.

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

namespace palpate {

/// Job: plain data with a `uint8_t* buffer` member (the buffer it carries).
template <class Job>
class BufferJobQueue {
 public:
  /// Allocates `buffers` (at least 1) zeroed buffers of `bytes` bytes each.
  BufferJobQueue(std::size_t buffers, std::size_t bytes) {
    const std::size_t n = std::max<std::size_t>(buffers, 1);
    pool_.resize(n);
    free_.reserve(n);
    for (auto& b : pool_) {
      b.assign(bytes, 0);
      free_.push_back(b.data());
    }
    ring_.resize(n);
  }
  BufferJobQueue(const BufferJobQueue&) = delete;
  BufferJobQueue& operator=(const BufferJobQueue&) = delete;

  /// A free buffer, or nullptr when none is free (block=false) or the queue is closed; block=true waits for one.
  uint8_t* acquire(bool block) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (block) buffer_free_.wait(lock, [this] { return !free_.empty() || closed_; });
    if (free_.empty() || closed_) return nullptr;
    uint8_t* b = free_.back();
    free_.pop_back();
    return b;
  }
  /// Queues a job holding an acquired buffer; false after close() (the buffer is free again, the job not queued).
  bool push(const Job& job) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (closed_) {
        free_.push_back(job.buffer);
        return false;
      }
      ring_[(head_ + size_) % ring_.size()] = job;
      ++size_;
    }
    job_ready_.notify_one();
    return true;
  }
  /// The oldest job, waiting for one; false once the queue is closed and drained (closing still drains).
  bool pop(Job* job) {
    std::unique_lock<std::mutex> lock(mutex_);
    job_ready_.wait(lock, [this] { return size_ > 0 || closed_; });
    if (size_ == 0) return false;
    *job = ring_[head_];
    head_ = (head_ + 1) % ring_.size();
    --size_;
    return true;
  }
  /// Gives a popped job's buffer back to the producer.
  void release(uint8_t* buffer) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      free_.push_back(buffer);
    }
    buffer_free_.notify_one();
  }
  /// No more jobs: the workers drain what is queued, then pop() returns false; a waiting acquire() returns nullptr.
  void close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    job_ready_.notify_all();
    buffer_free_.notify_all();
  }
  /// True when `buffer` is one of the pool's.
  bool owns(const uint8_t* buffer) const {
    return std::any_of(pool_.begin(), pool_.end(), [buffer](const auto& b) { return b.data() == buffer; });
  }

 private:
  std::vector<std::vector<uint8_t>> pool_;  // the buffers (n x bytes)
  std::mutex mutex_;
  std::condition_variable job_ready_;    // workers wait: a job or closing
  std::condition_variable buffer_free_;  // producer waits: a free buffer or closing
  std::vector<uint8_t*> free_;           // free buffers (capacity n)
  std::vector<Job> ring_;                // queued jobs (capacity n)
  std::size_t head_ = 0;                 // oldest queued job
  std::size_t size_ = 0;                 // jobs queued
  bool closed_ = false;
};

}  // namespace palpate
