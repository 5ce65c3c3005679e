#include "haptics/shm_segment.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
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

}  // namespace

ShmSegment::~ShmSegment() {
  if (seg_) munmap(seg_, kSize);
}

ShmSegment::ShmSegment(ShmSegment&& o) noexcept : seg_(std::exchange(o.seg_, nullptr)), name_(std::move(o.name_)) {}

ShmSegment& ShmSegment::operator=(ShmSegment&& o) noexcept {
  if (this != &o) {
    if (seg_) munmap(seg_, kSize);
    seg_ = std::exchange(o.seg_, nullptr);
    name_ = std::move(o.name_);
  }
  return *this;
}

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
  void* p = mmap(nullptr, kSize, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
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
      munmap(p, kSize);
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
    void* p = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
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
      return s;
    }
    munmap(p, size);
    // an unpublished segment may still be being set up by its device
    if (magic == PALPATE_SHIM_MAGIC || last_try) return err;
    sleep_until_ns(monotonic_ns() + 10'000'000);
  }
}

}  // namespace palpate
