#pragma once
/// SpscQueue<T>: bounded lock-free single-producer single-consumer ring buffer.
/// Storage is allocated in the constructor only; try_push / try_pop never allocate, lock or block.

#include <atomic>
#include <cstddef>
#include <new>
#include <optional>
#include <vector>

namespace palpate {

inline constexpr std::size_t kCacheLine = 64;

/// Bounded SPSC queue. Thread: exactly one producer thread calls try_push, one consumer calls try_pop.
/// Not copyable or movable.
template <class T>
class SpscQueue {
 public:
  /// A queue that holds up to `capacity` items (capacity >= 1).
  explicit SpscQueue(std::size_t capacity) : slots_(capacity + 1) {}
  SpscQueue(const SpscQueue&) = delete;
  SpscQueue& operator=(const SpscQueue&) = delete;

  /// Appends a copy of `item`; false (and nothing changes) when the queue is full. Thread: producer.
  [[nodiscard]] bool try_push(const T& item) noexcept {
    const std::size_t w = write_.load(std::memory_order_relaxed);
    const std::size_t next = w + 1 == slots_.size() ? 0 : w + 1;
    if (next == read_cached_) {
      read_cached_ = read_.load(std::memory_order_acquire);
      if (next == read_cached_) return false;
    }
    slots_[w] = item;
    write_.store(next, std::memory_order_release);
    return true;
  }

  /// Removes the oldest item into *out; false when empty. Thread: consumer.
  [[nodiscard]] bool try_pop(T* out) noexcept {
    const std::size_t r = read_.load(std::memory_order_relaxed);
    if (r == write_cached_) {
      write_cached_ = write_.load(std::memory_order_acquire);
      if (r == write_cached_) return false;
    }
    *out = slots_[r];
    read_.store(r + 1 == slots_.size() ? 0 : r + 1, std::memory_order_release);
    return true;
  }

  /// The oldest item, left in the queue (valid until the next try_pop); null when empty. Thread: consumer.
  [[nodiscard]] const T* front() noexcept {
    const std::size_t r = read_.load(std::memory_order_relaxed);
    if (r == write_cached_) {
      write_cached_ = write_.load(std::memory_order_acquire);
      if (r == write_cached_) return nullptr;
    }
    return &slots_[r];
  }

  /// Number of items the queue can hold.
  std::size_t capacity() const noexcept { return slots_.size() - 1; }

 private:
  std::vector<T> slots_;  // ring storage (capacity + 1), one slot kept empty
  alignas(kCacheLine) std::atomic<std::size_t> write_{0};
  alignas(kCacheLine) std::size_t read_cached_ = 0;   // producer's copy of read_
  alignas(kCacheLine) std::atomic<std::size_t> read_{0};
  alignas(kCacheLine) std::size_t write_cached_ = 0;  // consumer's copy of write_
};

}  // namespace palpate
