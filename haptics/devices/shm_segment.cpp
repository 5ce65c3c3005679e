#include "haptics/devices/shm_segment.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cstdint>
#include <mutex>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>

#include "core/clock.h"

namespace palpate {
namespace {

constexpr auto kSize = sizeof(palpate_shim_segment);

std::string octal(unsigned mode) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04o", mode & 07777u);
  return buf;
}

// Owner and mode checks shared by both sides.
Status check_owner(int fd, const std::string& what, struct stat* st) {
  if (fstat(fd, st) != 0) return make_error(what, ": fstat: ", std::strerror(errno));
  if (st->st_uid != geteuid())
    return make_error(what, ": owned by uid ", std::to_string(st->st_uid), ", not by this user (uid ",
                      std::to_string(geteuid()), "); refusing");
  if ((st->st_mode & 077u) != 0)
    return make_error(what, ": mode ", octal(st->st_mode), " lets other users access it (expected 0600); refusing");
  return Ok{};
}


// ---- truncation guard ----
// Another process of the same user can shrink the segment's file under a mapping; touching the lost pages then
// raises SIGBUS, which would kill the process (and the recording with its summary). Each mapping is registered
// here; the handler puts zero-filled private pages over a registered mapping that faulted, marks it lost and
// returns, so the access is retried on zeros: the peer's heartbeat stops and the link is seen as gone. A fault
// anywhere else goes to the handler that was there before (or the default: the process dies as it would have).
constexpr int kGuardSlots = 16;
struct GuardSlot {
  std::atomic<uintptr_t> begin{0};
  std::atomic<uintptr_t> end{0};
  std::atomic<bool> lost{false};
};
GuardSlot g_slots[kGuardSlots];
struct sigaction g_previous_bus {};
std::once_flag g_guard_once;

void on_sigbus(int sig, siginfo_t* info, void* context) {
  const auto addr = reinterpret_cast<uintptr_t>(info->si_addr);
  for (GuardSlot& slot : g_slots) {
    const uintptr_t b = slot.begin.load(std::memory_order_acquire), e = slot.end.load(std::memory_order_acquire);
    if (b != 0 && addr >= b && addr < e) {
      // mmap is a plain system call, safe in a handler; the same range, so no other mapping is touched
      void* p = ::mmap(reinterpret_cast<void*>(b), e - b, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED,
                       -1, 0);
      if (p != MAP_FAILED) {
        slot.lost.store(true, std::memory_order_release);
        return;
      }
    }
  }
  if (g_previous_bus.sa_flags & SA_SIGINFO) {
    if (g_previous_bus.sa_sigaction) return g_previous_bus.sa_sigaction(sig, info, context);
  } else if (g_previous_bus.sa_handler != SIG_DFL && g_previous_bus.sa_handler != SIG_IGN) {
    return g_previous_bus.sa_handler(sig);
  }
  // default action: the fault repeats on return and ends the process
  ::signal(SIGBUS, SIG_DFL);
}

int guard_mapping(void* p, std::size_t size) {
  std::call_once(g_guard_once, [] {
    struct sigaction sa {};
    sa.sa_sigaction = on_sigbus;
    sa.sa_flags = SA_SIGINFO | SA_NODEFER;
    sigemptyset(&sa.sa_mask);
    ::sigaction(SIGBUS, &sa, &g_previous_bus);
  });
  for (int i = 0; i < kGuardSlots; ++i) {
    uintptr_t expected = 0;
    GuardSlot& slot = g_slots[i];
    // claimed by end first (begin stays 0 until the slot is whole, so the handler never sees half a slot)
    if (slot.end.compare_exchange_strong(expected, reinterpret_cast<uintptr_t>(p) + size)) {
      slot.lost.store(false, std::memory_order_relaxed);
      slot.begin.store(reinterpret_cast<uintptr_t>(p), std::memory_order_release);
      return i;
    }
  }
  return -1;  // more mappings than slots: this one is unguarded (as every one was before)
}

void unguard_mapping(int slot) {
  if (slot < 0) return;
  g_slots[slot].begin.store(0, std::memory_order_release);
  g_slots[slot].end.store(0, std::memory_order_release);
}

void* map_segment(int fd, std::size_t size, int* slot) {
  void* p = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  *slot = p == MAP_FAILED ? -1 : guard_mapping(p, size);
  return p;
}

void unmap_segment(void* p, std::size_t size, int slot) {
  unguard_mapping(slot);
  munmap(p, size);
}

}  // namespace

ShmSegment::~ShmSegment() {
  if (seg_) unmap_segment(seg_, kSize, guard_);
}

ShmSegment::ShmSegment(ShmSegment&& o) noexcept
    : seg_(std::exchange(o.seg_, nullptr)), name_(std::move(o.name_)), guard_(std::exchange(o.guard_, -1)) {}

ShmSegment& ShmSegment::operator=(ShmSegment&& o) noexcept {
  if (this != &o) {
    if (seg_) unmap_segment(seg_, kSize, guard_);
    seg_ = std::exchange(o.seg_, nullptr);
    name_ = std::move(o.name_);
    guard_ = std::exchange(o.guard_, -1);
  }
  return *this;
}

bool ShmSegment::lost() const noexcept { return guard_ >= 0 && g_slots[guard_].lost.load(std::memory_order_acquire); }

Status ShmSegment::check_name(const std::string& name) {
  if (name.empty() || name.size() > PALPATE_SHIM_NAME_MAX)
    return make_error("shm name '", name, "': length ", std::to_string(name.size()), " out of range [1, ",
                      std::to_string(PALPATE_SHIM_NAME_MAX), "]");
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'))
      return make_error("shm name '", name, "': character '", std::string(1, c), "' not allowed (use A-Z a-z 0-9 _ - .)");
  return Ok{};
}

// True while `pid` is a live process (not gone, not a zombie waiting to be reaped).
static bool process_alive(pid_t pid) {
  if (::kill(pid, 0) != 0 && errno == ESRCH) return false;
  std::FILE* f = std::fopen(("/proc/" + std::to_string(pid) + "/stat").c_str(), "r");
  if (!f) return true;  // no /proc: kill() said it exists
  char buf[512] = {};
  const std::size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  // "pid (comm) S ...": the state follows the last ')'
  const std::string stat(buf, n);
  const std::size_t close = stat.rfind(')');
  if (close == std::string::npos || close + 2 >= stat.size()) return true;
  const char state = stat[close + 2];
  return state != 'Z' && state != 'X';
}

bool ShmSegment::unlink(const std::string& name) { return shm_unlink(path_of(name).c_str()) == 0; }

Result<ShmSegment> ShmSegment::serve(const std::string& name, const palpate_shim_specs& specs) {
  if (auto st = check_name(name); !st) return st.error();
  const std::string what = "shm '" + name + "' (/dev/shm" + path_of(name) + ")";
  int fd = shm_open(path_of(name).c_str(), O_RDWR | O_CREAT, 0600);
  if (fd < 0) return make_error(what, ": ", std::strerror(errno));
  struct stat st {};
  if (auto ok = check_owner(fd, what, &st); !ok) {
    close(fd);
    return ok.error();
  }
  bool fresh = static_cast<std::size_t>(st.st_size) != kSize;
  if (fresh && st.st_size != 0) {
    // a segment of another layout: replace it (a sim mapped to it could never have accepted it)
    close(fd);
    shm_unlink(path_of(name).c_str());
    fd = shm_open(path_of(name).c_str(), O_RDWR | O_CREAT | O_EXCL, 0600);
    if (fd < 0) return make_error(what, ": ", std::strerror(errno));
  }
  if (fresh && ftruncate(fd, static_cast<off_t>(kSize)) != 0) {
    const int e = errno;
    close(fd);
    return make_error(what, ": cannot size it: ", std::strerror(e));
  }
  int guard = -1;
  void* p = map_segment(fd, kSize, &guard);
  close(fd);
  if (p == MAP_FAILED) return make_error(what, ": mmap: ", std::strerror(errno));
  auto* seg = static_cast<palpate_shim_segment*>(p);
  const bool compatible = !fresh && __atomic_load_n(&seg->header.magic, __ATOMIC_ACQUIRE) == PALPATE_SHIM_MAGIC &&
                          seg->header.version == PALPATE_SHIM_VERSION && seg->header.segment_size == kSize;
  if (compatible) {
    // a single writer: a device process that still lives (even stopped by a signal) keeps its link
    const auto pid = static_cast<pid_t>(__atomic_load_n(&seg->header.device_pid, __ATOMIC_ACQUIRE));
    const bool stopped = __atomic_load_n(&seg->header.device_state, __ATOMIC_ACQUIRE) == PALPATE_SHIM_DEVICE_STOPPED;
    if (pid > 0 && pid != getpid() && !stopped && process_alive(pid)) {
      unmap_segment(p, kSize, guard);
      return make_error(what, ": already served by device process ", std::to_string(pid),
                        " (stop it first, or choose another --name)");
    }
    // re-attach after an earlier device process: keep the counters monotonic, mend a record it died inside
    palpate_shim_lock_repair(&seg->pose.lock);
    __atomic_store_n(&seg->header.device_state, uint64_t{PALPATE_SHIM_DEVICE_STARTING}, __ATOMIC_RELEASE);
  } else {
    __atomic_store_n(&seg->header.magic, uint64_t{0}, __ATOMIC_RELEASE);
    std::memset(static_cast<void*>(seg), 0, kSize);
    seg->header.version = PALPATE_SHIM_VERSION;
    seg->header.segment_size = static_cast<uint32_t>(kSize);
  }
  seg->specs = specs;
  seg->header.device_pid = static_cast<uint64_t>(getpid());
  __atomic_fetch_add(&seg->header.device_epoch, uint64_t{1}, __ATOMIC_RELEASE);
  __atomic_store_n(&seg->header.magic, PALPATE_SHIM_MAGIC, __ATOMIC_RELEASE);
  ShmSegment s;
  s.seg_ = seg;
  s.name_ = name;
  s.guard_ = guard;
  return s;
}

Result<ShmSegment> ShmSegment::connect(const std::string& name, double timeout_s) {
  if (auto st = check_name(name); !st) return st.error();
  const std::string what = "shm '" + name + "' (/dev/shm" + path_of(name) + ")";
  const int64_t deadline_ns = monotonic_ns() + static_cast<int64_t>(timeout_s * 1e9);
  for (;;) {
    const bool last_try = monotonic_ns() >= deadline_ns;
    const int fd = shm_open(path_of(name).c_str(), O_RDWR, 0);
    if (fd < 0) {
      if (errno != ENOENT) return make_error(what, ": ", std::strerror(errno));
      if (last_try) return make_error(what, ": no device serves it (start: palpate-device --name ", name, " ...)");
      sleep_until_ns(monotonic_ns() + 10'000'000);
      continue;
    }
    struct stat st {};
    if (auto ok = check_owner(fd, what, &st); !ok) {
      close(fd);
      return ok.error();
    }
    const auto size = static_cast<std::size_t>(st.st_size);
    if (size < sizeof(palpate_shim_header)) {
      close(fd);
      if (last_try) return make_error(what, ": segment is ", std::to_string(size), " bytes, expected ", std::to_string(kSize));
      sleep_until_ns(monotonic_ns() + 10'000'000);
      continue;
    }
    int guard = -1;
    void* p = map_segment(fd, size, &guard);
    close(fd);
    if (p == MAP_FAILED) return make_error(what, ": mmap: ", std::strerror(errno));
    auto* seg = static_cast<palpate_shim_segment*>(p);
    const uint64_t magic = __atomic_load_n(&seg->header.magic, __ATOMIC_ACQUIRE);
    Error err;
    if (magic != PALPATE_SHIM_MAGIC) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "0x%016llx", static_cast<unsigned long long>(magic));
      err = make_error(what, ": not a Palpate shim segment (magic ", buf, ")");
    } else if (seg->header.version != PALPATE_SHIM_VERSION) {
      err = make_error(what, ": device speaks shim version ", std::to_string(seg->header.version),
                       ", this build speaks version ", std::to_string(PALPATE_SHIM_VERSION));
    } else if (seg->header.segment_size != kSize || size != kSize) {
      err = make_error(what, ": segment size ", std::to_string(seg->header.segment_size), " (file ",
                       std::to_string(size), " bytes), this build expects ", std::to_string(kSize));
    } else {
      ShmSegment s;
      s.seg_ = seg;
      s.name_ = name;
      s.guard_ = guard;
      return s;
    }
    unmap_segment(p, size, guard);
    // an unpublished segment may still be being set up by its device
    if (magic == PALPATE_SHIM_MAGIC || last_try) return err;
    sleep_until_ns(monotonic_ns() + 10'000'000);
  }
}

}  // namespace palpate
