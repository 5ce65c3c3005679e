// The mesh reader in a forked child (core/mesh_reader_child.h).
#include "core/mesh_reader_child.h"

#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/uio.h>
#include <sys/wait.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace palpate {
namespace {

// a file descriptor closed when it goes out of scope
struct Fd {
  int fd = -1;
  explicit Fd(int f) : fd(f) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

// what the child sends: this header, then the vertices (3 doubles each) and triangles (3 int32 each) when ok,
// else the error message
struct ChildRecord {
  uint32_t magic = 0;
  uint32_t ok = 0;
  uint64_t a = 0;  // ok: vertex count; else message length
  uint64_t b = 0;  // ok: triangle count
};
constexpr uint32_t kRecordMagic = 0x504d5348;  // "PMSH"
static_assert(sizeof(Vec3) == 3 * sizeof(double), "vertices are sent as packed doubles");
static_assert(sizeof(std::array<int32_t, 3>) == 3 * sizeof(int32_t), "triangles are sent as packed int32");

bool write_all(int fd, std::array<iovec, 3> iov) {
  std::size_t first = 0;
  while (first < iov.size()) {
    if (iov[first].iov_len == 0) {
      ++first;
      continue;
    }
    const ssize_t n = ::writev(fd, &iov[first], static_cast<int>(iov.size() - first));
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    auto left = static_cast<std::size_t>(n);
    while (first < iov.size() && left >= iov[first].iov_len) {
      left -= iov[first].iov_len;
      ++first;
    }
    if (first < iov.size()) {
      iov[first].iov_base = static_cast<char*>(iov[first].iov_base) + left;
      iov[first].iov_len -= left;
    }
  }
  return true;
}

bool read_all_at(int fd, void* data, std::size_t size, off_t offset) {
  auto* p = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t n = ::pread(fd, p, size, offset);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
    offset += n;
  }
  return true;
}

// The child: the reader's crash signals back to their default action (a crash must end the child, whatever the
// parent installed), read, write one record to the memfd in one go, _exit (no exit handlers, no buffers flushed).
[[noreturn]] void run_child(MeshReader read, const std::string& path, int out_fd, int delay_ms) {
  for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) std::signal(sig, SIG_DFL);
  if (delay_ms > 0) {
    timespec t{delay_ms / 1000, static_cast<long>(delay_ms % 1000) * 1000000L};
    while (::nanosleep(&t, &t) != 0 && errno == EINTR) {
    }
  }
  Result<TriMesh> r = read(path);
  ChildRecord rec;
  rec.magic = kRecordMagic;
  bool written = false;
  if (r) {
    TriMesh& m = r.value();
    rec.ok = 1;
    rec.a = m.vertices_m.size();
    rec.b = m.triangles.size();
    written = write_all(out_fd, {iovec{&rec, sizeof rec}, iovec{m.vertices_m.data(), m.vertices_m.size() * sizeof(Vec3)},
                                 iovec{m.triangles.data(), m.triangles.size() * sizeof(m.triangles[0])}});
  } else {
    const std::string& msg = r.error().message;
    rec.a = msg.size();
    written = write_all(out_fd, {iovec{&rec, sizeof rec}, iovec{const_cast<char*>(msg.data()), msg.size()}, iovec{nullptr, 0}});
  }
  ::_exit(written ? 0 : 3);
}

std::string signal_name(int sig) {
  const char* abbrev = ::sigabbrev_np(sig);
  return abbrev != nullptr ? std::string("SIG") + abbrev : "signal " + std::to_string(sig);
}

// Waits for the child until the deadline; true with its wait status, false when the time ran out (child still
// running).
bool wait_child(pid_t pid, double limit_s, int* status) {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(limit_s));
  const Fd pidfd(static_cast<int>(::syscall(SYS_pidfd_open, pid, 0)));
  for (;;) {
    const pid_t w = ::waitpid(pid, status, WNOHANG);
    if (w == pid) return true;
    if (w < 0 && errno != EINTR) {
      *status = -1;
      return true;
    }
    const auto now = Clock::now();
    if (now >= deadline) return false;
    const auto left_ms = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - now).count() + 1;
    if (pidfd.fd >= 0) {
      pollfd p{pidfd.fd, POLLIN, 0};
      ::poll(&p, 1, static_cast<int>(std::min<long long>(left_ms, 1000)));
    } else {
      // no pidfd (old kernel): look again every millisecond
      timespec t{0, 1000000L};
      ::nanosleep(&t, nullptr);
    }
  }
}

}  // namespace

Result<TriMesh> read_mesh_in_child(const std::string& path, MeshReader read, double limit_s, int child_delay_ms_for_test) {
  const std::string who = "mesh '" + path + "': ";
  const Fd out(::memfd_create("palpate_mesh", MFD_CLOEXEC));
  if (out.fd < 0)
    return make_error(who, "could not run the mesh reader in a child process (memfd_create: ", std::strerror(errno), ")");
  const pid_t pid = ::fork();
  if (pid < 0) return make_error(who, "could not run the mesh reader in a child process (fork: ", std::strerror(errno), ")");
  if (pid == 0) run_child(read, path, out.fd, child_delay_ms_for_test);

  int status = 0;
  if (!wait_child(pid, limit_s, &status)) {
    ::kill(pid, SIGKILL);
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    char text[64];
    std::snprintf(text, sizeof text, "%.3g", limit_s);
    return make_error(who, "the mesh reader (assimp) took longer than ", text,
                      " s on this file and was stopped; the file is malformed or too large");
  }
  if (status == -1) return make_error(who, "could not run the mesh reader in a child process (waitpid: ", std::strerror(errno), ")");
  if (WIFSIGNALED(status))
    return make_error(who, "the mesh reader (assimp) crashed on this file (", signal_name(WTERMSIG(status)),
                      "); the file is malformed or unsupported");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return make_error(who, "the mesh reader (assimp) crashed on this file (exit status ", std::to_string(WEXITSTATUS(status)),
                      "); the file is malformed or unsupported");

  // the record: a header and exactly the arrays (or the message) it announces
  struct stat st {};
  ChildRecord rec;
  const auto no_record = [&] { return make_error(who, "could not run the mesh reader in a child process (no complete result)"); };
  if (::fstat(out.fd, &st) != 0 || !read_all_at(out.fd, &rec, sizeof rec, 0) || rec.magic != kRecordMagic) return no_record();
  const auto size = static_cast<uint64_t>(st.st_size) - sizeof rec;
  if (rec.ok == 0) {
    if (rec.a != size) return no_record();
    std::string message(rec.a, '\0');
    if (!read_all_at(out.fd, message.data(), message.size(), sizeof rec)) return no_record();
    return Error{std::move(message)};
  }
  if (rec.a > size / sizeof(Vec3) || rec.b > size / sizeof(std::array<int32_t, 3>) ||
      rec.a * sizeof(Vec3) + rec.b * sizeof(std::array<int32_t, 3>) != size)
    return no_record();
  TriMesh mesh;
  mesh.vertices_m.resize(rec.a);
  mesh.triangles.resize(rec.b);
  if (!read_all_at(out.fd, mesh.vertices_m.data(), rec.a * sizeof(Vec3), sizeof rec) ||
      !read_all_at(out.fd, mesh.triangles.data(), rec.b * sizeof(mesh.triangles[0]),
                   static_cast<off_t>(sizeof rec + rec.a * sizeof(Vec3))))
    return no_record();
  return mesh;
}


}  // namespace palpate
