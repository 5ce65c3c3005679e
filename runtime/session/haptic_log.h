#pragma once
/// HapticLog: haptic.csv, one row per servo tick, written as "<path>.partial" and renamed on close.

#include <string>

#include "core/atomic_file.h"
#include "core/result.h"
#include "haptics/servo/haptic_sample.h"

namespace palpate {

/// CSV writer. Thread: the sim thread only. Not copyable.
class HapticLog {
 public:
  HapticLog() = default;
  HapticLog(const HapticLog&) = delete;
  HapticLog& operator=(const HapticLog&) = delete;

  /// Opens "<path>.partial" (an AtomicFile: never through a link, never over a device) and writes the header.
  /// Errors name the path.
  Status open(const std::string& path);
  /// Appends one row; the first write error is kept and later rows are skipped.
  void append(const HapticSample& s);
  /// Flushes, closes and renames to the final name. Errors name the path (e.g. disk full); then what the failed
  /// write left is kept as "<path>.partial" (whole rows only) when it could be, and kept_path()/kept_rows() say so.
  Status close();
  /// Rows handed to the stream (before close(): all of them, whether or not they reach the disk).
  int64_t rows() const { return rows_; }
  /// After close(): the file that holds the log, "<path>" when complete, "<path>.partial" after a failed write,
  /// empty when none is left.
  const std::string& kept_path() const { return kept_path_; }
  /// After close(): the rows in kept_path() (the header not counted; 0 when none is kept).
  int64_t kept_rows() const { return kept_rows_; }

 private:
  AtomicFile file_;
  int64_t rows_ = 0;
  std::string kept_path_;
  int64_t kept_rows_ = 0;
};

}  // namespace palpate
