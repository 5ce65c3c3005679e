#pragma once
/// Keys of index pairs for hash sets and maps (edges, springs).

#include <algorithm>
#include <cstdint>

namespace palpate {

/// The same 64-bit key for (a, b) and (b, a).
inline uint64_t unordered_pair_key(int32_t a, int32_t b) {
  const auto lo = static_cast<uint32_t>(std::min(a, b)), hi = static_cast<uint32_t>(std::max(a, b));
  return (static_cast<uint64_t>(lo) << 32) | hi;
}

/// A key for the ordered pair (a, b): directed edges.
inline uint64_t ordered_pair_key(int32_t a, int32_t b) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

}  // namespace palpate
