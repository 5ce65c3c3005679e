#pragma once
/// MeshLayers: splits a mesh into what a frame may change (moving vertices, the triangles whose shading
/// depends on them, the edges that touch them) and the static rest, drawn once into a cached layer.

#include <array>
#include <cstdint>
#include <vector>

namespace palpate {

/// The split of one mesh for one set of moving vertices; grow-only buffers, copyable. Thread: the render thread.
class MeshLayers {
 public:
  /// Splits `triangles` (indices valid for n_vertices) and the unique `edges` (GL_LINES pairs) for `moving`:
  /// a triangle is dynamic when any of its vertices is moving or has a normal that depends on a moving vertex
  /// (a vertex of a triangle that has a moving vertex); an edge is dynamic when either end is moving.
  void split(std::size_t n_vertices, const std::vector<std::array<int32_t, 3>>& triangles,
             const std::vector<uint32_t>& edges, const std::vector<int32_t>& moving);

  /// Static triangles as GL index triples, in mesh order (3 n_static).
  const std::vector<uint32_t>& static_triangles() const { return static_tris_; }
  /// Dynamic triangles as GL index triples, in mesh order (3 n_dynamic).
  const std::vector<uint32_t>& dynamic_triangles() const { return dynamic_tris_; }
  /// Static edges as GL_LINES pairs (2 n_static_edges).
  const std::vector<uint32_t>& static_edges() const { return static_edges_; }
  /// Dynamic edges as GL_LINES pairs (2 n_dynamic_edges).
  const std::vector<uint32_t>& dynamic_edges() const { return dynamic_edges_; }
  /// Vertices whose position or normal a frame may change, ascending (n_affected).
  const std::vector<int32_t>& affected_vertices() const { return affected_; }

 private:
  std::vector<uint8_t> state_;  // per vertex: 0 static, 1 normal depends on a moving vertex, 2 moving (n_v)
  std::vector<uint32_t> static_tris_, dynamic_tris_, static_edges_, dynamic_edges_;
  std::vector<int32_t> affected_;
};

}  // namespace palpate
