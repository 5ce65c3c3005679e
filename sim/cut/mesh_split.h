#pragma once
/// Splitting a triangle mesh along a cut: every mesh edge the blade's swept surface crosses gets two new
/// vertices at the crossing, one for each side (placed below it as the incision's groove, cut_incision.h), and
/// the triangles around it are re-triangulated so the two sides share no vertex there. No cap triangles are added.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/types.h"
#include "sim/cut/cut.h"
#include "sim/cut/cut_incision.h"
#include "sim/lattice/mesh_normals.h"
#include "sim/cut/triangle_grid.h"

namespace palpate {

/// A vertex created on a cut edge: at from + t (to - from), on the side of vertex `from`. Plain data.
struct SplitVertex {
  int32_t from = 0;  ///< the edge end whose side the new vertex belongs to
  int32_t to = 0;    ///< the other end
  double t = 0.0;    ///< position along from -> to, in (0, 1)
};

/// A triangle the cut entered through one edge only (its crack tip): kept as two triangles opening from the
/// crossing to the far corner, and split again from its original shape when a later sweep reaches it, so a cut
/// made over many frames separates as one made at once. Plain data.
struct TipTriangle {
  std::array<int32_t, 3> tri{};       ///< the original triangle
  int32_t edge_lo = 0, edge_hi = 0;   ///< its crossed edge (lower, higher vertex id)
  int32_t copy_lo = 0, copy_hi = 0;   ///< the crossing's vertex on the side of edge_lo / edge_hi
  std::array<int32_t, 2> slot{};      ///< where its two halves are in the triangle list
};

/// What one split did. The split formula: triangles_added = tris_one_cut + 2 (tris_two_cut + tris_three_cut)
/// - tips_reopened, vertices_added = 2 edges_cut.
struct MeshSplitReport {
  int edges_cut = 0;        ///< mesh edges crossed by the swept surface
  int tris_one_cut = 0;     ///< triangles with one crossed edge (the cut ends inside): 1 -> 2, opening to the far corner
  int tips_reopened = 0;    ///< crack-tip triangles of earlier splits taken back to their original shape first
  int tris_two_cut = 0;     ///< triangles crossed through: 1 -> 3 (a corner triangle and a quad)
  int tris_three_cut = 0;   ///< triangles with all edges crossed: 1 -> 3 corner triangles (the middle is removed)
  int triangles_added = 0;  ///< growth of the triangle count
  int triangles_tested = 0; ///< triangles near the sweep whose edges were tested (the split's work)
  int vertices_added = 0;   ///< growth of the vertex count
};

/// A crossing closer than this fraction of an edge to one of its ends is ignored (no sliver triangles; a cut
/// along an existing cut does not split the vertices already on it again).
inline constexpr double kSplitEdgeEps = 1e-3;

/// Splits *triangles along the quads (rest coordinates), testing edges at the rest positions *rest_m; new vertices are
/// appended to *rest_m (at incision_point() of the crossing under `incision`; at the crossing for an all-zero
/// shape) and *current_m (interpolated at the crossing, moved as at rest) and listed in *created (cleared first) in
/// the same order. Winding is kept. Only the triangles *grid finds near the quads are visited: a split triangle's
/// first piece takes its place, the others are appended (and registered in *grid). *tips (in/out) lists the
/// crack-tip triangles and where their halves are. *changes (when non-null) gets every slot written, with the
/// triangle it held before. Cost: the triangles in the cubes the quads overlap, not the mesh.
MeshSplitReport split_mesh(const std::vector<BladeQuad>& quads, std::vector<Vec3>* rest_m, std::vector<Vec3>* current_m,
                           std::vector<std::array<int32_t, 3>>* triangles, std::vector<SplitVertex>* created,
                           std::vector<TipTriangle>* tips, TriangleGrid* grid, const IncisionShape& incision = {},
                           std::vector<TriangleChange>* changes = nullptr);

/// The first problem that makes this not a valid triangle mesh, or "" when there is none: an index out of range,
/// a repeated index, a triangle of (near) zero area, two triangles on the same three vertices, or a directed edge
/// used by two triangles.
std::string mesh_problem(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles);

/// Connected components of triangles (sharing a vertex); *label gets one id per triangle when non-null.
int triangle_components(std::size_t num_vertices, const std::vector<std::array<int32_t, 3>>& triangles,
                        std::vector<int32_t>* label = nullptr);

}  // namespace palpate
