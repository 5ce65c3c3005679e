#pragma once
// Counts heap allocations made by this thread (or by any thread) while a guard is alive, and fails one on purpose
// (global operator new is replaced in alloc_counter.cpp, linked into the test executables that include this header).

#include <cstdint>

namespace palpate::test {

/// Allocations counted since the guard was made. Thread: the creating thread only.
class AllocationGuard {
 public:
  AllocationGuard();
  ~AllocationGuard();
  /// Number of operator new / malloc-through-new calls seen on this thread.
  int64_t count() const;
};

/// Allocations counted on every thread since the guard was made: for a loop on a thread the test did not create
/// (start it first, make the guard, then wait for the loop to end). One at a time. Thread: any.
class AllThreadsAllocationGuard {
 public:
  AllThreadsAllocationGuard();
  ~AllThreadsAllocationGuard();
  /// Number of operator new calls seen on any thread.
  int64_t count() const;
};

/// Makes the n-th operator new on any thread, counted from construction (n >= 1), fail once as the real one does:
/// the new_handler, when one is installed, is called (if it returns, the allocation is tried again), else
/// std::bad_alloc is thrown; every allocation after it succeeds again (memory freed by the unwinding, as after a
/// real failure). One at a time.
class AllocationFault {
 public:
  explicit AllocationFault(int64_t n);
  ~AllocationFault();
  /// True once the n-th allocation has thrown.
  bool fired() const;
};

}  // namespace palpate::test
