#pragma once
/// Percentiles of recorded samples (timings), computed off the real-time path.

#include <algorithm>
#include <cmath>
#include <vector>

namespace palpate {

/// The q-quantile (0..1) of values by nearest rank; 0 for an empty set. Copies and sorts.
inline double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double rank = std::ceil(q * static_cast<double>(values.size()));
  const std::size_t idx = rank < 1.0 ? 0 : static_cast<std::size_t>(rank) - 1;
  return values[std::min(idx, values.size() - 1)];
}

}  // namespace palpate
