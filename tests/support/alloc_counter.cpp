#include "support/alloc_counter.h"

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace {
thread_local bool g_counting = false;
thread_local int64_t g_count = 0;
std::atomic<bool> g_all_counting{false};
std::atomic<int64_t> g_all_count{0};
std::atomic<bool> g_fault_armed{false};
std::atomic<bool> g_fault_fired{false};
std::atomic<int64_t> g_fault_countdown{0};

void* counted_alloc(std::size_t n, std::size_t align) {
  if (g_counting) ++g_count;
  if (g_all_counting.load(std::memory_order_relaxed)) g_all_count.fetch_add(1, std::memory_order_relaxed);
  if (g_fault_armed.load(std::memory_order_relaxed) && g_fault_countdown.fetch_sub(1) == 1) {
    g_fault_armed.store(false);
    g_fault_fired.store(true);
    // as the real operator new: the new_handler first (it may free memory and return: try again), else throw
    if (std::new_handler h = std::get_new_handler()) {
      h();
    } else {
      throw std::bad_alloc();
    }
  }
  void* p = align > alignof(std::max_align_t) ? std::aligned_alloc(align, (n + align - 1) / align * align) : std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n, alignof(std::max_align_t)); }
void* operator new[](std::size_t n) { return counted_alloc(n, alignof(std::max_align_t)); }
void* operator new(std::size_t n, std::align_val_t a) { return counted_alloc(n, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return counted_alloc(n, static_cast<std::size_t>(a)); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace palpate::test {

AllocationGuard::AllocationGuard() {
  g_count = 0;
  g_counting = true;
}
AllocationGuard::~AllocationGuard() { g_counting = false; }
int64_t AllocationGuard::count() const { return g_count; }

AllThreadsAllocationGuard::AllThreadsAllocationGuard() {
  g_all_count.store(0);
  g_all_counting.store(true);
}
AllThreadsAllocationGuard::~AllThreadsAllocationGuard() { g_all_counting.store(false); }
int64_t AllThreadsAllocationGuard::count() const { return g_all_count.load(); }

AllocationFault::AllocationFault(int64_t n) {
  g_fault_fired.store(false);
  g_fault_countdown.store(n < 1 ? 1 : n);
  g_fault_armed.store(true);
}
AllocationFault::~AllocationFault() { g_fault_armed.store(false); }
bool AllocationFault::fired() const { return g_fault_fired.load(); }

}  // namespace palpate::test
