#pragma once
/// AtomicFile: an output file written under a temporary name beside it and renamed over the final name only
/// when every byte reached the disk, so a failure never leaves half a file (or a replaced device) behind.

#include <cstdio>
#include <string>
#include <string_view>

#include "core/result.h"

namespace palpate {

/// One output being written. Refuses a final path that is a symbolic link or names anything but a regular file
/// (a device such as /dev/null, a FIFO, a socket, a folder); the temporary "<path><suffix>" is created with
/// O_CREAT | O_EXCL | O_NOFOLLOW (a file or link left there is removed first, never followed). Every write,
/// the flush, fsync and close are checked; the first failure is kept with its errno text. Errors read
/// "<what> '<path>': <cause>". Movable, not copyable; destroying it uncommitted removes the temporary.
/// Thread: one thread at a time.
class AtomicFile {
 public:
  AtomicFile() = default;
  ~AtomicFile();
  AtomicFile(AtomicFile&& other) noexcept;
  AtomicFile& operator=(AtomicFile&& other) noexcept;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Checks the final path and creates the temporary; `what` names the output in errors ("summary", "png").
  static Result<AtomicFile> open(const std::string& path, const std::string& what, const std::string& suffix = ".tmp");

  /// Appends bytes; a failed write is kept as the error and later writes are skipped.
  void write(std::string_view bytes);
  /// The stdio stream of the temporary, for formatted writes (fprintf); errors show up in commit().
  std::FILE* stream() { return f_; }
  /// Records a failure found by the caller (errno text or a message) unless one is already kept.
  void fail(const std::string& cause);
  /// True while no write failed.
  bool good() const { return error_.empty() && f_ != nullptr; }

  /// Flushes, fsyncs and closes the temporary without renaming it (commit() then only renames), so several
  /// files can reach the disk in parallel and still appear under their final names in a chosen order. Errors
  /// as commit's; after a failure commit() reports it again and removes the temporary.
  Status sync();
  /// Flushes, fsyncs and closes the temporary (unless sync() did), checks the final path again and renames. On failure the
  /// temporary is removed unless keep_partial: then it is cut after its last newline (a line-oriented log such as
  /// haptic.csv keeps its whole rows, never half a row a full disk tore) and the error says where it is kept.
  Status commit(bool keep_partial = false);
  /// Closes and removes the temporary without touching the final path.
  void discard();

  /// The final path.
  const std::string& path() const { return path_; }
  /// The temporary path.
  std::string temp_path() const { return path_ + suffix_; }

 private:
  std::string path_, what_, suffix_;
  std::FILE* f_ = nullptr;
  std::string error_;
  bool synced_ = false;  // sync() closed the temporary; commit() renames it
};

/// Writes `bytes` to `path` through an AtomicFile; errors as AtomicFile's.
Status write_file_atomic(const std::string& path, std::string_view bytes, const std::string& what);

/// Checks that `path` may be replaced by an output: absent, or a regular file that is not a symbolic link.
/// Errors: "<what> '<path>': is a symbolic link, not written through", "... is not a regular file (a device,
/// FIFO, socket or folder), not replaced".
/// A target that does not exist yet must have its folder, unless folder_made_later (the run makes it): so a bench's
/// output into a missing folder is refused before its minutes of measuring, naming the folder.
Status check_output_target(const std::string& path, const std::string& what, bool folder_made_later = false);

}  // namespace palpate
