#pragma once
/// MeshNormals: vertex normals of a mesh whose triangles and positions change in a few places a frame (a cut). Each
/// vertex keeps the ascending ids of its triangles, so a change recomputes only the normals around it, bit for bit
/// as compute_vertex_normals() (core/tri_mesh.h) would: the same face normals summed in the same triangle order.

#include <array>
#include <cstdint>
#include <vector>

#include "core/types.h"

namespace palpate {

/// One triangle slot written by a mesh split: its triangle before (all -1 for a slot appended) and now. Plain data.
struct TriangleChange {
  int32_t slot = 0;                        ///< index in the triangle list
  std::array<int32_t, 3> before{-1, -1, -1};  ///< the triangle it held (-1s: appended)
};

/// Triangles by vertex and the changes not yet taken into the normals. Copyable. Thread: the sim thread.
class MeshNormals {
 public:
  /// Indexes the triangles of a mesh of n_vertices vertices; every normal counts as stale until the first update().
  void reset(std::size_t n_vertices, const std::vector<std::array<int32_t, 3>>& triangles);
  /// The slots of `changes` now hold triangles[slot] (the mesh may have grown to n_vertices): the triangle lists of
  /// their old and new corners are brought up to date and those corners' normals marked stale.
  void retriangulate(std::size_t n_vertices, const std::vector<TriangleChange>& changes,
                     const std::vector<std::array<int32_t, 3>>& triangles);
  /// Every normal is stale (the whole mesh moved).
  void invalidate() { all_stale_ = true; }
  /// Vertex v moved: the normals of every vertex of its triangles are stale.
  void moved(int32_t v) { moved_.push_back(v); }
  /// Brings *normals (what the last call left; grown to the vertex count) up to date with vertices_m and triangles:
  /// all of them after reset() or invalidate(), or when *normals is longer than the mesh, else only the stale ones.
  /// Returns how many normals were recomputed.
  std::size_t update(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                     std::vector<Vec3>* normals);
  /// The triangles of vertex v, ascending.
  const std::vector<int32_t>& triangles_of(int32_t v) const { return tris_of_[static_cast<std::size_t>(v)]; }

 private:
  std::vector<std::vector<int32_t>> tris_of_;  // ascending triangle ids of each vertex (n_v)
  std::vector<int32_t> moved_;                 // vertices moved since the last update
  std::vector<int32_t> stale_;                 // vertices whose triangles changed since the last update
  std::vector<int32_t> work_;                  // scratch: the normals to recompute
  bool all_stale_ = true;                      // reset() since the last update
};

}  // namespace palpate
