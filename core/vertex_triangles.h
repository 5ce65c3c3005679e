#pragma once
/// VertexTriangles: which triangles meet at each vertex, and the normals that follow from it for a few vertices,
/// so a frame that moves k vertices recomputes O(k) normals instead of the whole mesh's.

#include <array>
#include <cstdint>
#include <vector>

#include "core/types.h"

namespace palpate {

/// Vertex -> triangle adjacency in compressed rows; plain data, copyable. A triangle appears once per corner
/// (twice at a vertex it repeats), in ascending triangle order, so sums over it follow the mesh's order.
struct VertexTriangles {
  std::vector<int32_t> offsets;    ///< row start per vertex (n_v + 1)
  std::vector<int32_t> triangles;  ///< triangle ids, rows concatenated (3 n_t)

  /// Builds the adjacency of n_vertices vertices in O(n_v + n_t); indices must be in [0, n_vertices).
  static VertexTriangles build(std::size_t n_vertices, const std::vector<std::array<int32_t, 3>>& triangles);
  /// Number of vertices indexed.
  std::size_t num_vertices() const { return offsets.empty() ? 0 : offsets.size() - 1; }
};

/// Recomputes the normals of the listed vertices bit for bit as compute_vertex_normals computes them (same
/// face normals, summed in the same order); other normals are untouched. O(sum of the listed vertices' degrees).
void update_vertex_normals(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                           const VertexTriangles& adjacency, const std::vector<int32_t>& vertex_ids,
                           std::vector<Vec3>* normals);

/// The vertices whose normal changes when any of `moving` moves: every vertex of a triangle with a moving vertex
/// (each listed once, ascending). mark is scratch of n_v bytes, left all zero.
void normal_dependents(const std::vector<std::array<int32_t, 3>>& triangles, const VertexTriangles& adjacency,
                       const std::vector<int32_t>& moving, std::vector<uint8_t>* mark, std::vector<int32_t>* out);

}  // namespace palpate
