#pragma once
/// HapticLog: haptic.csv, one row per servo tick, written as "<path>.partial" and renamed on close.

#include <cstdio>
#include <string>

#include "core/result.h"
#include "haptics/haptic_sample.h"

namespace palpate {

/// CSV writer. Thread: the sim thread only. Not copyable.
class HapticLog {
 public:
  HapticLog() = default;
  ~HapticLog();
  HapticLog(const HapticLog&) = delete;
  HapticLog& operator=(const HapticLog&) = delete;

  /// Opens "<path>.partial" and writes the header. Errors name the path.
  Status open(const std::string& path);
  /// Appends one row; the first write error is kept and later rows are skipped.
  void append(const HapticSample& s);
  /// Flushes, closes and renames to the final name. Errors name the path (e.g. disk full).
  Status close();
  /// Rows written.
  int64_t rows() const { return rows_; }

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
  int64_t rows_ = 0;
  std::string error_;
};

}  // namespace palpate
