#pragma once
/// CutModel: a mesh that can be cut, bound to a lattice so each side of a cut follows its own nodes.
///
/// Side binding: every vertex keeps its cell (eq. 1) and a mask of the cell's corners that a cut separates it
/// from (the straight rest segment vertex -> corner node crosses the blade's swept surface mapped to rest).
/// A vertex is moved by the trilinear weights of its unmasked corners only, renormalised, so the two sides of a
/// cut cell follow the nodes on their own side; a vertex with no corner left on its side (a sliver) takes the
/// nearest nodes on its side among the neighbouring cells.

#include <array>
#include <cstdint>
#include <vector>

#include "core/binding.h"
#include "core/grid_hierarchy.h"
#include "core/tri_mesh.h"
#include "sim/cut/cut.h"
#include "sim/cut/cut_incision.h"
#include "sim/lattice/lattice.h"
#include "sim/lattice/mesh_normals.h"
#include "sim/cut/mesh_split.h"
#include "sim/cut/rest_map.h"
#include "sim/cut/triangle_box_grid.h"
#include "sim/cut/triangle_grid.h"

namespace palpate {

/// The distance a rest quad is moved off its plane, in lattice cells: a mesh edge is split only where crossed
/// farther than kSplitEdgeEps of its length from an end, so a vertex on the blade's plane would leave its edges
/// uncut (a blade along a row of vertices splitting nothing); moved, every vertex and node is on one side.
inline constexpr double kBladeOffsetCells = 0.01;

/// A blade piece mapped to rest may sweep at most this many times what it swept in the world (plus half a cell),
/// and be at most this many cells long; one beyond was mapped across a gap (into a piece that fell away) and is
/// dropped.
inline constexpr double kMaxRestStretch = 2.0;

/// What one apply() changed.
struct CutReport {
  int springs_cut = 0;         ///< springs removed
  MeshSplitReport split;       ///< mesh split figures
  int vertices_rebound = 0;    ///< existing vertices that lost a corner to the cut
  int quads_dropped = 0;       ///< rest quads whose map jumped (kMaxRestStretch), left uncut
  int quads_cut = 0;           ///< rest quads (cell-sized blade pieces) this apply cut with
  int vertices_tested = 0;     ///< existing vertices whose corners were tested (those bound to a cell a quad reaches)
  /// The apply's cut work, in the unit the work limit counts: triangles tested plus vertices tested.
  int work() const { return split.triangles_tested + vertices_tested; }
  bool changed() const { return springs_cut > 0 || split.edges_cut > 0 || vertices_rebound > 0; }
};

/// Mesh, side binding and pending blade sweeps of a cut session. Copyable. Thread: the sim thread.
class CutModel {
 public:
  /// Starts from the uncut mesh at rest and its bindings at `level` of `grid` (which must outlive this).
  CutModel(const TriMesh& rest, const std::vector<VertexBinding>& bindings, const GridHierarchy* grid, int level,
           double blade_length_m);

  /// Records one servo sample's blade: tip position, unit axis from tip toward the handle, and whether it cuts.
  /// Consecutive cutting samples add the quad their blade edges sweep; a non-cutting sample ends the stroke.
  void add_sample(const Vec3& tip_m, const Vec3& axis, bool cutting);
  /// Quads waiting for apply().
  const std::vector<BladeQuad>& pending() const { return pending_; }
  /// True when the next apply() has something to do: quads swept, quads queued, springs deferred.
  bool has_work() const { return !pending_.empty() || !queued_.empty() || !deferred_.empty(); }
  /// At most about n work items per apply() (0: no limit, the default): an item is a triangle the split tests
  /// (those registered in the rest cubes a quad reaches) or a vertex whose corners the side binding tests (those
  /// bound to a lattice cell a quad's box overlaps). The quads mapped to rest wait in order in a queue and each
  /// apply() takes from its front while the items of the cubes and cells they reach stay within n (always at
  /// least one quad), so a long or fast stroke is cut over several frames and CutReport::work() stays within n
  /// plus one quad's items; but always at least a quarter of the queue, so the cut is never more than about four
  /// applies behind the blade (on a mesh so dense that the limit lets through less than a frame's stroke).
  void set_max_cut_work_per_apply(int n) { max_work_ = std::max(n, 0); }
  /// Rest quads mapped but not cut yet.
  std::size_t queued_quads() const { return queued_.size(); }
  /// Cuts the lattice springs and the mesh with the pending quads, mapped into rest coordinates through the
  /// current lattice (rest_map.h) and tested against rest positions; *vertices_m (current) grows by the new
  /// vertices. Updates the side binding and clears the pending quads.
  CutReport apply(Lattice* lat, std::vector<Vec3>* vertices_m);
  /// Cuts with the given quads, in world coordinates (as apply() does with the pending ones). Each quad is
  /// mapped to rest and moved by kBladeOffsetCells of a cell along one fixed direction, so a blade through a
  /// row of vertices or nodes still has them all on one side.
  CutReport apply_quads(const std::vector<BladeQuad>& quads, Lattice* lat, std::vector<Vec3>* vertices_m);
  /// At most n springs leave the lattice per apply() (0: no limit, the default), or a quarter of those waiting
  /// when more wait, so none waits much more than four applies; the others crossed stay until a later apply()
  /// (oldest first), which then runs even with no quads pending. The mesh is cut at once. Each spring removed
  /// costs the local/global factor a downdate: on bunny_cut a blade stroke crosses about 60 springs every
  /// fourth frame, 5-7 ms of downdates in one frame.
  void set_max_springs_per_apply(int n) { max_springs_ = std::max(n, 0); }
  int max_springs_per_apply() const { return max_springs_; }
  /// The incision's groove depth in lattice cells (cut_incision.h; default kIncisionDepthCells, 0: the copies a
  /// split makes stay at the crossing and a slit that does not open is not seen). Negative counts as 0.
  void set_incision_depth_cells(double cells) { incision_cells_ = std::max(cells, 0.0); }
  /// The blade's width, metres: the two copies of a crossing are set this far apart across the swept surface
  /// (cut_incision.h; default 0: they meet in the groove). Negative counts as 0.
  void set_incision_gap_m(double gap_m) { incision_gap_m_ = std::max(gap_m, 0.0); }
  /// Springs crossed by the blade and still in the lattice.
  std::size_t deferred_springs() const { return deferred_.size(); }
  /// Moves every vertex whose cell is in the lattice with its side's nodes; others stay at rest.
  void deform(const Lattice& lat, std::vector<Vec3>* vertices_m) const;
  /// The same result as deform() into the *vertices_m this was last called with (the first call moves every vertex),
  /// computing only the vertices that can have changed since: those of cells with a node that moved, those the cuts
  /// since created or cut off from a corner, and those following a fallback node that moved. Those whose position
  /// changed are handed to normals(). Returns how many vertices were computed.
  std::size_t deform_changed(const Lattice& lat, std::vector<Vec3>* vertices_m);
  /// Brings *normals up to date with *vertices_m after the cuts and deform_changed() calls since the last call (all
  /// of them the first time): compute_vertex_normals()' result, bit for bit. Returns how many normals were recomputed.
  std::size_t update_normals(const std::vector<Vec3>& vertices_m, std::vector<Vec3>* normals) {
    return normals_.update(vertices_m, triangles_, normals);
  }

  /// Current triangles.
  const std::vector<std::array<int32_t, 3>>& triangles() const { return triangles_; }
  /// Rest positions of the current vertices.
  const std::vector<Vec3>& rest_vertices_m() const { return rest_m_; }
  /// Corners each vertex is cut off from (bit = corner dx + 2dy + 4dz).
  const std::vector<uint8_t>& blocked() const { return blocked_; }
  /// Writes the ids of triangles whose current box overlaps [lo_m, hi_m] into *out (cleared first), ascending.
  /// vertices_m must be the rest positions or what apply() and deform_changed() / deform() last wrote: the triangles
  /// they changed are moved in a grid of current boxes (TriangleBoxGrid, built at rest with the model), and only
  /// those near the box are tested.
  void triangles_in_box(const std::vector<Vec3>& vertices_m, const Vec3& lo_m, const Vec3& hi_m,
                        std::vector<int32_t>* out) const;
  /// Triangles whose box the last triangles_in_box() tested.
  std::size_t last_box_tested() const { return box_grid_.last_tested(); }
  /// Appends the lattice cells (linear index at the bound level) whose box overlaps [lo_m, hi_m] to *cells.
  void cells_in_box(const Vec3& lo_m, const Vec3& hi_m, std::vector<int32_t>* cells) const;
  /// Appends the vertices bound to `cell` (linear index at the bound level) to *out, in no set order.
  void vertices_in_cell(int32_t cell, std::vector<int32_t>* out) const {
    for (int32_t v = cell_first_[static_cast<std::size_t>(cell)]; v >= 0; v = next_in_cell_[static_cast<std::size_t>(v)])
      out->push_back(v);
  }
  /// The triangles by rest cube (every triangle of the cut mesh is registered).
  const TriangleGrid& triangle_grid() const { return tri_grid_; }
  /// The rest quads the last apply() cut with.
  const std::vector<BladeQuad>& last_quads() const { return last_batch_; }
  /// Vertices moved by the fallback (no corner left on their side) in the last deform().
  int orphans() const { return orphans_; }

 private:
  // cuts springs and mesh with a batch of rest quads
  CutReport cut_rest(const std::vector<BladeQuad>& quads, Lattice* lat, std::vector<Vec3>* vertices_m);
  // springs the next apply() removes at most (max_springs_ > 0)
  int springs_this_apply() const;
  // marks the corners of vertex v (seen from test point p) that the quads separate it from; true when changed
  bool block_corners(const Lattice& lat, std::size_t v, const Vec3& p_m, const CutQuads& quads);
  // links vertex v into its cell's list
  void link_vertex(int32_t v);
  // nearest node of the cells around vertex v that the quads do not separate from p (-1 if none)
  int32_t nearest_visible_node(const Lattice& lat, std::size_t v, const Vec3& p_m, const CutQuads& quads) const;
  // vertex v moved with its side's nodes (or its rest position outside the lattice); *orphan: by the fallback rule
  Vec3 deformed(const Lattice& lat, std::size_t v, bool* orphan) const;

  const GridHierarchy* grid_;
  int level_;
  double blade_length_m_;
  std::vector<Vec3> rest_m_;                      // rest positions (n_v)
  std::vector<std::array<int32_t, 3>> triangles_; // (n_t)
  std::vector<VertexBinding> bindings_;           // cell and local coordinates (n_v)
  std::vector<uint8_t> blocked_;                  // corners cut off (n_v)
  std::vector<int32_t> fallback_;                 // node followed when every corner is cut off, else -1 (n_v)
  std::vector<BladeQuad> pending_;                // swept quads not applied yet
  std::vector<BladeQuad> queued_;                 // rest quads mapped, not cut yet (split budget)
  std::vector<BladeQuad> last_batch_;             // rest quads the last apply() cut with
  int max_work_ = 0;                              // triangles and vertices tested per apply() at most (0: all)
  std::vector<int32_t> cell_first_;               // first vertex bound to each cell at level_, -1: none (n_cells)
  std::vector<int32_t> next_in_cell_;             // next vertex of the same cell, -1: last (n_v)
  std::vector<int32_t> cell_count_;               // vertices bound to each cell (n_cells)
  TriangleGrid tri_grid_;                         // triangles by rest cube
  int max_springs_ = 0;                           // springs removed per apply() at most (0: all)
  double incision_cells_ = kIncisionDepthCells;   // groove depth, lattice cells
  double incision_gap_m_ = 0.0;                   // the copies' distance apart across the swept surface, metres
  std::vector<uint64_t> deferred_;                // crossed springs still in the lattice, oldest first
  RestEdge last_edge_;                            // the last blade edge mapped to rest
  std::vector<TipTriangle> tips_;                 // crack tips: their halves end triangles_
  bool have_prev_ = false;                        // the previous sample was cutting
  Vec3 prev_tip_m_ = Vec3::Zero(), prev_end_m_ = Vec3::Zero();
  mutable int orphans_ = 0;
  MeshNormals normals_;                           // triangles by vertex, stale normals
  std::vector<TriangleChange> changes_;           // scratch: the slots the last split wrote
  std::vector<Vec3> x_deformed_m_;                // node positions at the last deform_changed(), empty before (n)
  std::vector<int32_t> redeform_;                 // vertices created or rebound since the last deform_changed()
  std::vector<int32_t> fallback_users_;           // vertices given a fallback node
  std::vector<uint8_t> node_moved_;               // scratch: per node, moved since the last deform_changed() (n)
  // the patch search's grid of current triangle boxes (a cache: triangles_in_box() brings it up to date)
  mutable TriangleBoxGrid box_grid_;
  mutable std::vector<int32_t> box_stale_;        // triangles whose box changed since the grid saw them
  mutable bool box_all_stale_ = true;             // every triangle's (deform() moved any vertex)
  // marks the triangles of vertex v as moved in the patch search's grid
  void box_moved(int32_t v) const;
};

}  // namespace palpate
