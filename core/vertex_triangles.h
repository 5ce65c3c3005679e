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

/// The unit normal (zero when degenerate) of a vertex met by the `count` triangles `ids` (ascending), bit for bit as
/// compute_vertex_normals sums it.
Vec3 vertex_normal(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                   const int32_t* ids, std::size_t count);

/// The unit normal at corner `corner` (0..2) of triangle `tri` of a surface with creases, as a renderer's smoothing
/// groups take it: the sum of the face normals (area-weighted, of vertices_m) of the triangles at that corner's vertex
/// whose face turns from `tri`'s by less than the crease angle in the rest shape rest_m (cos_crease: its cosine; tri
/// itself always counts). A corner on a crease gets a normal for each side; a deformation never makes one. With
/// cos_crease <= -1 it is vertex_normal's. Zero when degenerate.
Vec3 crease_normal(const std::vector<Vec3>& vertices_m, const std::vector<Vec3>& rest_m,
                   const std::vector<std::array<int32_t, 3>>& triangles, const VertexTriangles& adjacency, int32_t tri,
                   int corner, double cos_crease);

/// Recomputes the normals of the listed vertices bit for bit as compute_vertex_normals computes them (same
/// face normals, summed in the same order); other normals are untouched. O(sum of the listed vertices' degrees).
void update_vertex_normals(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                           const VertexTriangles& adjacency, const std::vector<int32_t>& vertex_ids,
                           std::vector<Vec3>* normals);

/// The normals of one fixed set of vertices, recomputed as update_vertex_normals does (bit for bit the same) but
/// with each face normal computed once rather than once per corner. attach() when the set changes: O(k log k) in
/// the set's adjacency entries; update() per frame: O(k). Grow-only buffers, copyable.
class VertexNormalPatch {
 public:
  /// Takes the vertices (each once) and the triangles that meet them; indices must be valid for adjacency.
  void attach(const VertexTriangles& adjacency, const std::vector<int32_t>& vertex_ids);
  /// Writes the normals of the attached vertices into *normals (n_v); other normals are untouched.
  void update(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
              std::vector<Vec3>* normals);
  /// The attached vertices.
  const std::vector<int32_t>& vertex_ids() const { return vertex_ids_; }
  /// Number of distinct triangles whose face normals a frame computes.
  std::size_t num_triangles() const { return triangle_ids_.size(); }

 private:
  std::vector<int32_t> vertex_ids_;    // the attached vertices (k)
  std::vector<int32_t> triangle_ids_;  // the distinct triangles at them, ascending (n_f)
  std::vector<int32_t> offsets_;       // per attached vertex: start of its row in face_slots_ (k + 1)
  std::vector<int32_t> face_slots_;    // adjacency rows of the attached vertices, as indices into triangle_ids_
  std::vector<Vec3> faces_;            // face normals (unnormalised) of triangle_ids_ (n_f)
};

/// The vertices whose normal changes when any of `moving` moves: every vertex of a triangle with a moving vertex
/// (each listed once, ascending). mark is scratch of n_v bytes, left all zero.
void normal_dependents(const std::vector<std::array<int32_t, 3>>& triangles, const VertexTriangles& adjacency,
                       const std::vector<int32_t>& moving, std::vector<uint8_t>* mark, std::vector<int32_t>* out);

}  // namespace palpate
