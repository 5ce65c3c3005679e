#pragma once
/// GridHierarchy: the paper's grid hierarchy over the normalised cube (section 4.1), also the spatial index
/// used to find triangles near a point.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "core/aabb.h"
#include "core/result.h"
#include "core/tri_mesh.h"
#include "core/types.h"

namespace palpate {

/// Integer cell coordinates along x, y, z at one level; plain data.
struct CellCoord {
  int i = 0;  ///< x index, 0..cells_per_axis-1
  int j = 0;  ///< y index
  int k = 0;  ///< z index
};

/// Levels n = 1..k over a cube; level n splits each axis into 2^(n-1) cells, cell index i + n*(j + n*k).
/// Leaves (level k) list their vertices and the triangles overlapping them; every level has surface and solid
/// flags. Immutable after build(); copyable and movable; const methods may be called from any thread.
/// Index arguments are checked only by debug asserts.
class GridHierarchy {
 public:
  /// The finest level allowed (128^3 = 2M leaf cells).
  static constexpr int kMaxLevels = 8;

  /// An empty one-level grid over the unit cube centred at the origin (no vertices, no triangles); a
  /// placeholder to assign a built grid into.
  GridHierarchy();

  /// Builds `levels` levels over `cube` (a cube) for `mesh`, whose vertices must lie in the closed cube
  /// (points on the max faces belong to the last cell). Errors: "grid levels 9 out of range [1, 8]",
  /// "grid cube extent (1, 1, 2) is not a cube of positive finite side", "grid: triangle 5 vertex index 40 is
  /// beyond the vertex list (size 32)", "grid: vertex 12 at (0.6, 0, 0) lies outside the cube".
  static Result<GridHierarchy> build(const TriMesh& mesh, const Aabb& cube, int levels);

  /// Number of levels k.
  int levels() const { return levels_; }
  /// Cells along each axis at `level`: 2^(level-1).
  int cells_per_axis(int level) const { return 1 << (level - 1); }
  /// Cells at `level`: cells_per_axis^3.
  int64_t num_cells(int level) const;
  /// Side of one cell at `level`, metres.
  double cell_size_m(int level) const;
  /// The cube the grid covers.
  const Aabb& cube() const { return cube_; }

  /// The cell holding p_m at `level`, clamped into the grid; points on a max face go to the last cell.
  CellCoord cell_of(const Vec3& p_m, int level) const;
  /// Linear index i + n*(j + n*k) of a cell at `level`.
  int32_t linear_index(const CellCoord& c, int level) const;
  /// Cell coordinates of a linear index at `level`.
  CellCoord coord_of(int32_t index, int level) const;
  /// Base point b of a cell (its minimum corner), metres.
  Vec3 cell_min_m(const CellCoord& c, int level) const;
  /// Index of the parent cell at level - 1; requires level >= 2.
  int32_t parent(int32_t index, int level) const;
  /// Indices of the 8 children at level + 1 (bit 0 = +x, bit 1 = +y, bit 2 = +z); requires level < levels().
  std::array<int32_t, 8> children(int32_t index, int level) const;

  /// Vertex ids in a leaf cell (level == levels()), ascending.
  std::span<const int32_t> leaf_vertices(int32_t leaf) const;
  /// Triangle ids overlapping a leaf cell (closed box, conservative by 1e-9 of a cell), ascending.
  std::span<const int32_t> leaf_triangles(int32_t leaf) const;

  /// True when the cell holds a vertex or overlaps a triangle (any level).
  bool surface_cell(int32_t index, int level) const;
  /// True for surface cells and cells enclosed by them (not reached by a 6-connected flood of non-surface
  /// cells from the grid's outer border).
  bool solid_cell(int32_t index, int level) const;
  /// Fraction in [0, 1] of a leaf cell inside the mesh: 1 for solid cells the surface does not cross, 0 outside,
  /// and for surface cells the inside length of 4 x 4 lines along x through the cell by the parity of their crossings
  /// with the mesh (a line with an odd count, where the mesh is not closed, counts the cell whole).
  double leaf_solid_fraction(int32_t leaf) const;
  /// Number of surface cells at `level`.
  int64_t surface_cells(int level) const;
  /// Number of solid cells at `level`.
  int64_t solid_cells(int level) const;

  /// Number of mesh vertices indexed.
  std::size_t num_vertices() const { return num_vertices_; }
  /// Number of mesh triangles indexed.
  std::size_t num_triangles() const { return num_triangles_; }

  /// Writes into *out (cleared first, capacity reused) the ids, sorted and unique, of the triangles in the
  /// leaves that the box [lo_m, hi_m] touches: a superset of the triangles overlapping the box; empty when the
  /// box misses the cube. O(overlaps gathered): sorted by radix; scratch (grow-only, may be null) is its buffer.
  void triangles_near(const Vec3& lo_m, const Vec3& hi_m, std::vector<int32_t>* out,
                      std::vector<int32_t>* scratch = nullptr) const;

 private:
  void build_leaf_lists(const TriMesh& mesh);
  void build_flags();
  void build_solid_fractions(const TriMesh& mesh);

  int levels_ = 1;
  Aabb cube_{Vec3::Constant(-0.5), Vec3::Constant(0.5)};
  double side_m_ = 1.0;
  std::size_t num_vertices_ = 0;
  std::size_t num_triangles_ = 0;
  // leaf CSR: ids of leaf c are ids[offsets[c] .. offsets[c+1])
  std::vector<int32_t> leaf_vertex_offsets_;    // (num leaves + 1)
  std::vector<int32_t> leaf_vertex_ids_;        // (num vertices)
  std::vector<int32_t> leaf_triangle_offsets_;  // (num leaves + 1)
  std::vector<int32_t> leaf_triangle_ids_;      // (leaf/triangle overlaps)
  // per level (index level - 1): one byte per cell
  std::vector<std::vector<uint8_t>> surface_;
  std::vector<std::vector<uint8_t>> solid_;
  std::vector<int64_t> surface_count_;
  std::vector<int64_t> solid_count_;
  std::vector<float> leaf_solid_fraction_;       // (num leaves)
};

}  // namespace palpate
