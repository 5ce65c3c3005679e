#pragma once
/// MeshLayers: splits a mesh into what a frame may change (moving vertices, the triangles whose shading
/// depends on them, the edges that touch them) and the static rest, drawn once into a cached layer.

#include <array>
#include <cstdint>
#include <vector>

namespace palpate {

/// The split of one mesh for one set of moving vertices; grow-only buffers, copyable. Thread: the render thread.
///
/// The dynamic part is indexed into a compact vertex array of its own (local indices), so a frame hands GL only
/// the vertices it draws: local vertex i is mesh vertex local_vertices()[i]. The affected vertices come first,
/// in ascending order (local i == position in affected_vertices()), then the static vertices of dynamic
/// triangles, whose positions and normals stay what they were when the split was made.
class MeshLayers {
 public:
  /// Splits `triangles` (indices valid for n_vertices) and the unique `edges` (GL_LINES pairs) for `moving`:
  /// a triangle is dynamic when any of its vertices is moving or has a normal that depends on a moving vertex
  /// (a vertex of a triangle that has a moving vertex); an edge is dynamic when either end is moving.
  void split(std::size_t n_vertices, const std::vector<std::array<int32_t, 3>>& triangles,
             const std::vector<uint32_t>& edges, const std::vector<int32_t>& moving);

  /// The same split as split() would make after the mesh grew only inside the dynamic part (a cut): triangles at
  /// dynamic slots rewritten, triangles appended, vertices appended, all of them moving. O(dynamic part), not the
  /// mesh. False (nothing changed; split() again) when it cannot tell: edges given before, a moving vertex that
  /// was not, a new vertex not moving, or a triangle with a moving corner at a vertex of the static part.
  bool grow(std::size_t n_vertices, const std::vector<std::array<int32_t, 3>>& triangles,
            const std::vector<int32_t>& moving);

  /// Static triangles as GL index triples into the mesh, in mesh order (3 n_static).
  const std::vector<uint32_t>& static_triangles() const { return static_tris_; }
  /// Static edges as GL_LINES pairs into the mesh (2 n_static_edges).
  const std::vector<uint32_t>& static_edges() const { return static_edges_; }
  /// Dynamic triangles as GL index triples into local_vertices(), in mesh order (3 n_dynamic).
  const std::vector<uint32_t>& dynamic_triangles() const { return dynamic_tris_; }
  /// Dynamic edges as GL_LINES pairs into local_vertices(), in the order of `edges` (2 n_dynamic_edges).
  const std::vector<uint32_t>& dynamic_edges() const { return dynamic_edges_; }
  /// Vertices whose position or normal a frame may change, ascending (n_affected); local indices 0..n_affected-1.
  const std::vector<int32_t>& affected_vertices() const { return affected_; }
  /// The mesh vertex of each local index: affected_vertices(), then the other vertices the dynamic part uses.
  const std::vector<int32_t>& local_vertices() const { return local_; }

 private:
  std::vector<uint8_t> state_;  // per vertex: 0 static, 1 normal depends on a moving vertex, 2 moving (n_v)
  std::vector<int32_t> local_of_;  // per vertex: its local index, -1 when the dynamic part does not use it (n_v)
  std::vector<uint32_t> static_tris_, dynamic_tris_, static_edges_, dynamic_edges_;
  std::vector<int32_t> affected_, local_;
  std::vector<int32_t> dynamic_ids_;  // the dynamic triangles' slots, ascending (n_dynamic)
  std::size_t n_triangles_ = 0;       // triangles split
  bool had_edges_ = false;            // the split had edges
  // (re)numbers the dynamic triangles of dynamic_ids_ into local_ after the affected vertices
  void number_dynamic(const std::vector<std::array<int32_t, 3>>& triangles);
};

}  // namespace palpate
