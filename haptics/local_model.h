#pragma once
/// LocalModel: the sim's latest snapshot of the deformed surface near the tool, read by the servo.

#include <array>
#include <cstdint>

#include "core/types.h"

namespace palpate {

/// A fixed-capacity patch of deformed triangles. Plain data, copied through TripleBuffer (no allocation).
struct LocalModel {
  static constexpr int kMaxTriangles = 512;
  int64_t frame = -1;                                     ///< sim frame that produced it (-1 = none yet)
  int num_triangles = 0;                                  ///< triangles in use
  bool truncated = false;                                 ///< more triangles were near than fit
  std::array<int32_t, kMaxTriangles> tri_ids{};           ///< mesh triangle ids
  std::array<std::array<Vec3, 3>, kMaxTriangles> tri_m{}; ///< deformed corner positions
  std::array<std::array<Vec3, 3>, kMaxTriangles> normal{};///< unit vertex normals at the corners
};

}  // namespace palpate
