#pragma once
/// HapticLog: haptic.csv, one row per servo tick, written as "<path>.partial" and renamed on close.

#include <string>

#include "core/atomic_file.h"
#include "core/result.h"
#include "haptics/haptic_sample.h"

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
  /// Flushes, closes and renames to the final name. Errors name the path (e.g. disk full).
  Status close();
  /// Rows written.
  int64_t rows() const { return rows_; }

 private:
  AtomicFile file_;
  int64_t rows_ = 0;
};

}  // namespace palpate
