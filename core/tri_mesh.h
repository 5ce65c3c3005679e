#pragma once
/// TriMesh: an indexed triangle mesh (shared vertices, counter-clockwise outward triangles).

#include <array>
#include <cstdint>
#include <span>
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

/// Appends the triangles of one polygon (vertex ids into vertices_m, in order around it) to *triangles, wound as
/// the polygon: a triangle as it is, a convex polygon as a fan, a concave one (up to 1024 corners) by clipping ears
/// in the plane its Newell normal faces (a fan when that fails or for more corners). Fewer than 3 ids add nothing.
void append_polygon(const std::vector<Vec3>& vertices_m, std::span<const int32_t> polygon,
                    std::vector<std::array<int32_t, 3>>* triangles);

/// Merges vertices closer than tolerance_m (per coordinate: within a cube of that half-side) into the first of
/// them, renumbering the triangles; the order of the vertices kept is their first appearance. tolerance_m = 0
/// merges only identical positions (+0 and -0 alike). Returns the number of vertices merged away.
std::size_t weld_vertices(TriMesh* mesh, double tolerance_m);

}  // namespace palpate
