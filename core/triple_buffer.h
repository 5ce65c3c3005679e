#pragma once
/// TripleBuffer<T>: one writer publishes whole snapshots, one reader takes the latest; neither ever blocks.

#include <array>
#include <atomic>
#include <cstdint>

namespace palpate {

/// Lock-free triple buffer. Thread: one writer (write_buffer/publish), one reader (read).
/// T is copied in place, never allocated per call. Not copyable or movable.
template <class T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  /// The buffer the writer fills before publish(). Thread: writer.
  T& write_buffer() noexcept { return buffers_[write_]; }

  /// Makes the write buffer the latest snapshot. Thread: writer.
  void publish() noexcept {
    const uint8_t prev = middle_.exchange(static_cast<uint8_t>(write_ | kFresh), std::memory_order_acq_rel);
    write_ = prev & kIndexMask;
  }

  /// The latest published snapshot (the same one again when nothing new was published). Thread: reader.
  const T& read() noexcept {
    if (middle_.load(std::memory_order_relaxed) & kFresh) {
      const uint8_t prev = middle_.exchange(read_, std::memory_order_acq_rel);
      read_ = prev & kIndexMask;
      seen_ = true;
    }
    return buffers_[read_];
  }

  /// True once anything has been published. Thread: reader.
  bool has_data() const noexcept { return seen_ || (middle_.load(std::memory_order_acquire) & kFresh); }

 private:
  static constexpr uint8_t kFresh = 0x4;
  static constexpr uint8_t kIndexMask = 0x3;
  static constexpr uint8_t kInitialRead = 2;
  std::array<T, 3> buffers_{};
  uint8_t write_ = 0;                  // writer's private index
  std::atomic<uint8_t> middle_{1};     // shared index (+ fresh flag)
  uint8_t read_ = kInitialRead;        // reader's private index
  bool seen_ = false;                  // reader has taken at least one snapshot
};

}  // namespace palpate
