#include "runtime/record/memory_reserve.h"

#include <atomic>
#include <cstdlib>
#include <cstring>

namespace palpate {
namespace {

std::atomic<void*> g_reserve{nullptr};
std::atomic<bool> g_tripped{false};

// operator new calls this when an allocation fails, then tries again; throwing gives up
void give_reserve() {
  if (void* block = g_reserve.exchange(nullptr)) {
    std::free(block);
    g_tripped.store(true);
    return;
  }
  throw std::bad_alloc();
}

}  // namespace

MemoryReserve::MemoryReserve(std::size_t bytes) {
  g_tripped.store(false);
  void* block = std::malloc(bytes);
  if (block != nullptr) std::memset(block, 0, bytes);
  g_reserve.store(block);
  previous_ = std::set_new_handler(give_reserve);
}

MemoryReserve::~MemoryReserve() {
  std::set_new_handler(previous_);
  std::free(g_reserve.exchange(nullptr));
}

bool MemoryReserve::tripped() { return g_tripped.load(); }

}  // namespace palpate
