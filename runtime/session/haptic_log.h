#pragma once
/// HapticLog: haptic.csv, one row per servo tick, written as "<path>.partial" and renamed on close.

#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/result.h"
#include "haptics/servo/haptic_sample.h"

namespace palpate {

/// haptic.csv's header: the columns of each row, in order (the Python module names its arrays by these too).
inline constexpr const char* kHapticLogColumns =
    "tick,t_s,tool_x_m,tool_y_m,tool_z_m,proxy_x_m,proxy_y_m,proxy_z_m,force_x_N,force_y_N,force_z_N,contact,buttons,"
    "rejected,frame,model_frame,force_scale,controls,mode,stiffness_scale,tool_radius_m,resets";

/// The number of haptic.csv's columns.
inline constexpr int kHapticLogWidth = 22;

/// One sample's row as numbers, in kHapticLogColumns' order (the file writes the same values as text).
void haptic_log_values(const HapticSample& s, double out[kHapticLogWidth]);

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
  /// Also keeps every appended sample in `to` (may be null: none; must outlive the log), whatever reaches the
  /// disk: a caller that wants the rows in memory reads them there, not back from the file.
  void keep_samples(std::vector<HapticSample>* to) { keep_ = to; }
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
  std::vector<HapticSample>* keep_ = nullptr;
};

}  // namespace palpate
