#include "core/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>

namespace palpate {

Status check_output_target(const std::string& path, const std::string& what, bool folder_made_later) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) return make_error(what, " '", path, "': ", std::strerror(errno));
    std::error_code ec;
    const std::filesystem::path folder = std::filesystem::absolute(path, ec).parent_path().lexically_normal();
    if (!folder_made_later && !std::filesystem::is_directory(folder, ec))
      return make_error(what, " '", path, "': folder '", folder.string(), "' does not exist");
    return Ok{};
    return make_error(what, " '", path, "': ", std::strerror(errno));
  }
  if (S_ISLNK(st.st_mode)) return make_error(what, " '", path, "': is a symbolic link, not written through");
  if (!S_ISREG(st.st_mode))
    return make_error(what, " '", path, "': is not a regular file (a device, FIFO, socket or folder), not replaced");
  return Ok{};
}

namespace {

// Cuts the file at `path` after its last newline (to nothing when it has none), so what a failed write left of
// a line-oriented log is whole lines; shrinking needs no free space. Reads backwards from the end in blocks.
void cut_after_last_newline(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  struct stat st {};
  off_t keep = 0;
  if (::fstat(fd, &st) == 0) {
    char block[4096];
    for (off_t end = st.st_size; end > 0 && keep == 0;) {
      const off_t start = end > static_cast<off_t>(sizeof block) ? end - static_cast<off_t>(sizeof block) : 0;
      const ssize_t n = ::pread(fd, block, static_cast<std::size_t>(end - start), start);
      if (n != end - start) break;  // unreadable: cut to nothing rather than keep a torn line
      for (ssize_t i = n - 1; i >= 0; --i)
        if (block[i] == '\n') {
          keep = start + i + 1;
          break;
        }
      end = start;
    }
    if (keep < st.st_size) (void)::ftruncate(fd, keep);
  }
  ::close(fd);
}

}  // namespace

AtomicFile::~AtomicFile() { discard(); }

AtomicFile::AtomicFile(AtomicFile&& o) noexcept
    : path_(std::move(o.path_)), what_(std::move(o.what_)), suffix_(std::move(o.suffix_)), f_(std::exchange(o.f_, nullptr)),
      error_(std::move(o.error_)), synced_(std::exchange(o.synced_, false)) {}

AtomicFile& AtomicFile::operator=(AtomicFile&& o) noexcept {
  if (this != &o) {
    discard();
    path_ = std::move(o.path_);
    what_ = std::move(o.what_);
    suffix_ = std::move(o.suffix_);
    f_ = std::exchange(o.f_, nullptr);
    error_ = std::move(o.error_);
    synced_ = std::exchange(o.synced_, false);
  }
  return *this;
}

Result<AtomicFile> AtomicFile::open(const std::string& path, const std::string& what, const std::string& suffix) {
  if (path.empty()) return make_error(what, ": empty output path");
  // (a missing folder: the open below names the path and the system's reason)
  if (auto st = check_output_target(path, what, true); !st) return st.error();
  AtomicFile a;
  a.path_ = path;
  a.what_ = what;
  a.suffix_ = suffix;
  const std::string tmp = a.temp_path();
  // a temporary left by an earlier run (or a link planted there) is removed, never followed
  struct stat st {};
  if (::lstat(tmp.c_str(), &st) == 0 && (S_ISREG(st.st_mode) || S_ISLNK(st.st_mode))) ::unlink(tmp.c_str());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) return make_error(what, " '", path, "': cannot create '", tmp, "': ", std::strerror(errno));
  a.f_ = ::fdopen(fd, "wb");
  if (!a.f_) {
    const int e = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    return make_error(what, " '", path, "': ", std::strerror(e));
  }
  return a;
}

void AtomicFile::write(std::string_view bytes) {
  if (!good() || bytes.empty()) return;
  if (std::fwrite(bytes.data(), 1, bytes.size(), f_) != bytes.size()) fail(std::strerror(errno));
}

void AtomicFile::fail(const std::string& cause) {
  if (error_.empty()) error_ = cause.empty() ? "write failed" : cause;
}

Status AtomicFile::sync() {
  if (!f_) return make_error(what_, " '", path_, "': ", error_.empty() ? "not open" : error_);
  // the data reaches the disk (and ENOSPC shows up) at flush, fsync and close
  if (std::fflush(f_) != 0) fail(std::strerror(errno));
  if (std::ferror(f_)) fail("write failed");
  if (error_.empty() && ::fsync(fileno(f_)) != 0) fail(std::strerror(errno));
  if (std::fclose(f_) != 0) fail(std::strerror(errno));
  f_ = nullptr;
  synced_ = true;
  if (!error_.empty()) return make_error(what_, " '", path_, "': ", error_);
  return Ok{};
}

Status AtomicFile::commit(bool keep_partial) {
  if (!synced_) {
    if (!f_) return make_error(what_, " '", path_, "': ", error_.empty() ? "not open" : error_);
    (void)sync();  // its failure is in error_
  }
  synced_ = false;
  const std::string tmp = temp_path();
  if (error_.empty()) {
    if (auto st = check_output_target(path_, what_); !st) {
      ::unlink(tmp.c_str());
      return st;
    }
    if (std::rename(tmp.c_str(), path_.c_str()) == 0) return Ok{};
    fail(std::string("rename from '") + tmp + "': " + std::strerror(errno));
  } else if (keep_partial) {
    cut_after_last_newline(tmp);
    return make_error(what_, " '", path_, "': ", error_, " (partial data kept in ", tmp, ", up to its last whole line)");
  }
  ::unlink(tmp.c_str());
  return make_error(what_, " '", path_, "': ", error_);
}

void AtomicFile::discard() {
  if (!f_ && !synced_) return;
  if (f_) std::fclose(f_);
  f_ = nullptr;
  synced_ = false;
  ::unlink(temp_path().c_str());
}

Status write_file_atomic(const std::string& path, std::string_view bytes, const std::string& what) {
  auto f = AtomicFile::open(path, what);
  if (!f) return f.error();
  f.value().write(bytes);
  return f.value().commit();
}

}  // namespace palpate
