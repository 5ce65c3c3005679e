#pragma once
/// LatencyHistogram: 2000 fixed buckets (1 µs wide by default: up to 2 ms) plus an overflow count; add() never
/// allocates.

#include <array>
#include <cstdint>

namespace palpate {

/// Histogram of latencies in microseconds. Thread: one writer; read after the writer stops.
class LatencyHistogram {
 public:
  static constexpr int kBuckets = 2000;  ///< bucket i holds [i, i+1) bucket widths

  /// Buckets bucket_ns wide (1 µs for a servo; 100 µs covers a 60 Hz frame loop's 200 ms).
  explicit LatencyHistogram(int64_t bucket_ns = 1000) noexcept : bucket_ns_(bucket_ns > 0 ? bucket_ns : 1000) {}

  /// Records one latency in nanoseconds (negative values count as 0).
  void add(int64_t latency_ns) noexcept {
    const int64_t b = latency_ns < 0 ? 0 : latency_ns / bucket_ns_;
    if (b >= kBuckets) ++overflow_;
    else ++buckets_[static_cast<std::size_t>(b)];
    ++count_;
    if (latency_ns > max_ns_) max_ns_ = latency_ns;
  }
  /// Number of recorded values.
  int64_t count() const noexcept { return count_; }
  /// Values at or past range_us().
  int64_t overflow() const noexcept { return overflow_; }
  /// Upper end of the buckets, µs (2000 for 1 µs buckets).
  double range_us() const noexcept { return static_cast<double>(kBuckets * bucket_ns_) / 1000.0; }
  /// Bucket width, µs.
  double bucket_us() const noexcept { return static_cast<double>(bucket_ns_) / 1000.0; }
  /// Largest value in µs.
  double max_us() const noexcept { return static_cast<double>(max_ns_) / 1000.0; }
  /// Upper edge (µs) of the bucket holding quantile q in [0, 1]; max_us() when it falls in the overflow.
  double quantile_us(double q) const noexcept {
    if (count_ == 0) return 0.0;
    const auto need = static_cast<int64_t>(q * static_cast<double>(count_) + 0.999999);
    int64_t seen = 0;
    for (int i = 0; i < kBuckets; ++i) {
      seen += buckets_[static_cast<std::size_t>(i)];
      if (seen >= need) return (i + 1.0) * bucket_us();
    }
    return max_us();
  }
  /// Count in bucket i.
  int64_t bucket(int i) const noexcept { return buckets_[static_cast<std::size_t>(i)]; }

 private:
  int64_t bucket_ns_ = 1000;
  std::array<int64_t, kBuckets> buckets_{};
  int64_t overflow_ = 0;
  int64_t count_ = 0;
  int64_t max_ns_ = 0;
};

}  // namespace palpate
