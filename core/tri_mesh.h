#pragma once
/// TriMesh: an indexed triangle mesh (shared vertices, counter-clockwise outward triangles).

#include <array>
#include <cstdint>
#include <vector>

#include "core/types.h"

namespace palpate {

/// Indexed triangle mesh; plain data, copyable.
struct TriMesh {
  std::vector<Vec3> vertices_m;                   ///< vertex positions (n_v), metres
  std::vector<std::array<int32_t, 3>> triangles;  ///< vertex indices per triangle (n_t)

  std::size_t num_vertices() const { return vertices_m.size(); }
  std::size_t num_triangles() const { return triangles.size(); }
};

/// Per-vertex normals (area-weighted average of face normals, unit length; zero for isolated vertices).
void compute_vertex_normals(const std::vector<Vec3>& vertices_m,
                            const std::vector<std::array<int32_t, 3>>& triangles,
                            std::vector<Vec3>* normals);

/// Midpoint subdivision: every triangle becomes four, new vertices at edge midpoints (shared between neighbours).
/// Vertices: n_v + n_edges; triangles: 4 n_t. Used to make large meshes from small ones (benchmarks, tests).
TriMesh subdivide_midpoint(const TriMesh& mesh);

}  // namespace palpate
