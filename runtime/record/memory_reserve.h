#pragma once
/// A recording's reserve against running out of memory. While one is alive, an allocation that fails (operator
/// new's new_handler, called before it gives up) frees the reserve and is tried again, so what was under way —
/// a frame, a PNG on its encoder thread, the summary, or a destructor that allocates, where a throw would end the
/// process — completes; the frame loop then sees tripped() and stops the run with its line and summary. A second
/// failure with the reserve gone throws std::bad_alloc as before. One at a time (it owns the process's
/// new_handler). Thread: made and destroyed on one thread; the handler and tripped() on any.

#include <cstddef>
#include <new>

namespace palpate {

class MemoryReserve {
 public:
  /// Holds `bytes` (touched, so they are really there to give back) and installs the handler.
  explicit MemoryReserve(std::size_t bytes = kDefaultBytes);
  ~MemoryReserve();
  MemoryReserve(const MemoryReserve&) = delete;
  MemoryReserve& operator=(const MemoryReserve&) = delete;

  /// True once the reserve was given up to a failed allocation.
  static bool tripped();

  /// Enough for the frame under way, its PNG, the summary and the shutdown of a 640 x 480 recording.
  static constexpr std::size_t kDefaultBytes = std::size_t{16} << 20;

 private:
  std::new_handler previous_ = nullptr;
};

}  // namespace palpate
