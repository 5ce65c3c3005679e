#pragma once
/// StateHash: 64-bit FNV-1a over raw bytes, for bit-exact determinism checks of lockstep runs.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "core/types.h"

namespace palpate {

/// Incremental FNV-1a hash; feed values in a fixed order.
class StateHash {
 public:
  /// Adds raw bytes.
  void add_bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h_ ^= p[i];
      h_ *= 0x100000001b3ULL;
    }
  }
  /// Adds every coordinate of every point.
  void add(const std::vector<Vec3>& points) {
    for (const Vec3& p : points) add_bytes(p.data(), 3 * sizeof(double));
  }
  /// The hash so far.
  uint64_t value() const { return h_; }
  /// The hash as 16 lowercase hex digits.
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h_));
    return buf;
  }

 private:
  uint64_t h_ = 0xcbf29ce484222325ULL;
};

}  // namespace palpate
