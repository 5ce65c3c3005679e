#pragma once
/// Model: a scene's mesh loaded, normalised (paper step 1), indexed by the grid hierarchy (step 2) and bound (step 3).

#include <vector>

#include "core/aabb.h"
#include "core/binding.h"
#include "core/grid_hierarchy.h"
#include "core/mesh_orientation.h"
#include "core/result.h"
#include "core/scene.h"
#include "core/tri_mesh.h"
#include "core/vertex_triangles.h"

namespace palpate {

/// Immutable after load; shared read-only by the stages of a session.
struct Model {
  TriMesh rest;                          ///< normalised mesh at rest
  Normalization normalization;           ///< raw -> world mapping
  GridHierarchy grid;                    ///< hierarchy over the normalisation cube
  std::vector<VertexBinding> bindings;   ///< per vertex, at the lattice level (lattice.refine.level when refined)
  VertexTriangles adjacency;             ///< triangles at each vertex of `rest` (normals of moved vertices)
  double leaf_cell_m = 0.0;              ///< edge of a leaf cell
  bool closed = false;                   ///< touch scenes: every edge of `rest` is shared by exactly two triangles
  /// touch scenes on a surface that is not closed: each triangle's part (triangles joined through shared corners),
  /// the side of which a touch holds to; empty otherwise
  std::vector<int32_t> part_of;
  MeshOrientation orientation;           ///< what was turned outward at load (a mesh file's faces)
  int auto_subdivisions = 0;             ///< midpoint subdivisions mesh.subdivisions "auto" applied (0: none)
  double coarse_edge_m = 0.0;            ///< then: the file's median longest triangle edge, normalised (m)
};

/// The median over the finest lattice cell above which a surface is coarser than its lattice: the surface the tool
/// meets moves only at the triangles' corners, so a coarser one cannot dent under the tool.
inline constexpr double kCoarseMeshEdgeCells = 2.0;
/// Triangles mesh.subdivisions "auto" stops short of (each subdivision multiplies them by 4).
inline constexpr int64_t kAutoSubdivisionTriangles = int64_t{1} << 20;

/// The median of the triangles' longest edges (m; 0 for no triangles). O(triangles).
double median_longest_edge_m(const TriMesh& mesh);
/// The midpoint subdivisions that bring a median longest edge of median_edge_m to within kCoarseMeshEdgeCells of
/// cell_m (each halves every edge), at most 5 and while the triangles stay under kAutoSubdivisionTriangles.
int auto_subdivisions(double median_edge_m, double cell_m, int64_t triangles);

/// A point or direction of a mesh file with up axis `up_axis` ('x', 'y' or 'z') in world axes (its up becomes +z;
/// a right-handed rotation), before normalisation.
Vec3 file_to_world_axes(const Vec3& v, char up_axis);

/// Loads the scene's mesh (or generates its box), turns a mesh file's faces outward (orient_outward) and builds
/// grid and bindings. Errors name the mesh file, or the
/// scene when its lattice could pass kMaxLatticeNodes / kMaxLatticeSprings (sim/lattice/lattice_estimate.h).
Result<Model> load_model(const Scene& scene);

/// Whether the stiffest material a person may set (device.browser_stiffness_range's high end, core/scene_controls.h)
/// is one the scene's integrator steps stably on the model's cells; the error names the key and the check's message.
Status check_control_range(const Scene& scene, const Model& model);

/// Each triangle's part: triangles joined through shared corners have the same number, 0, 1, ... in the order the
/// parts' first triangles come.
std::vector<int32_t> triangle_parts(const TriMesh& mesh, const VertexTriangles& adjacency);

/// Whether every edge of mesh is shared by exactly two of its triangles (a closed surface, with an inside).
/// O(sum of squared vertex degrees).
bool closed_surface(const TriMesh& mesh, const VertexTriangles& adjacency);

}  // namespace palpate
