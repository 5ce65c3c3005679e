#pragma once
/// Turning a mesh's faces outward at load. Contact starts where the tool crosses a face from its front
/// (counter-clockwise side), so a closed model written with its faces wound inward, or with a patch of them turned,
/// is touched from inside or not at all. orient_outward walks each connected part across its shared edges, turns
/// the faces that disagree with their neighbours, and turns a closed part whose volume comes out negative inside
/// out (a cavity's closed wall inside another closed part the other way: it faces into the cavity).

#include <cstdint>
#include <string>

#include "core/tri_mesh.h"

namespace palpate {

/// What orient_outward did to a mesh; all zero when every face already faced out and agreed with its neighbours.
struct MeshOrientation {
  int64_t components = 0;          ///< parts connected across edges shared by exactly two triangles
  int64_t closed_components = 0;   ///< of those, parts with no open edge (they have an inside)
  int64_t triangles = 0;           ///< triangles in the mesh
  int64_t triangles_flipped = 0;   ///< triangles whose winding was reversed
  int64_t turned_inside_out = 0;   ///< closed parts whose faces all pointed inward (negative volume), turned
  int64_t made_consistent = 0;     ///< parts in which faces disagreeing with their neighbours were turned
  int64_t not_orientable = 0;      ///< parts left as they are: no winding agrees across all their edges
  int64_t cavities = 0;            ///< closed parts inside another closed part, turned to face into the cavity

  /// True when the mesh's triangles were changed.
  bool changed() const { return triangles_flipped > 0; }
  /// One line for the user naming what was turned ("turned 12 of 12 triangles: ..."), empty when nothing was.
  std::string notice() const;
};

/// Reverses the winding (swaps corners 1 and 2) of the triangles that face inward: in each part connected across
/// manifold edges, the faces that disagree with their neighbours (the smaller area of the two windings, for an open
/// part), and then, for a closed part, all of it when its signed volume is negative (positive for a cavity's wall
/// nested inside another closed part). Vertices, the order of the triangles and every triangle already facing out
/// are left as they are; a non-orientable part is left alone. O(n_t) plus, with several closed parts, a ray test
/// of each against those whose box holds it (nesting is not looked for among more than kMaxNestedParts parts).
MeshOrientation orient_outward(TriMesh* mesh);

/// Above this many closed parts, cavities are not looked for (each closed part then faces out on its own).
inline constexpr int64_t kMaxNestedParts = 256;

}  // namespace palpate
