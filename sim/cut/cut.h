#pragma once
/// Cutting the lattice: the surface a blade edge sweeps between two servo samples, segment tests against it,
/// removal of the springs it crosses, connected components, and a floor for pieces that fall.

#include <array>
#include <cstdint>
#include <vector>

#include "core/types.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// The surface swept by the blade edge between two samples: edge tip0-end0 moved to tip1-end1. Plain data.
struct BladeQuad {
  Vec3 tip0_m = Vec3::Zero();  ///< blade tip at the earlier sample
  Vec3 end0_m = Vec3::Zero();  ///< blade end (toward the handle) at the earlier sample
  Vec3 tip1_m = Vec3::Zero();  ///< blade tip at the later sample
  Vec3 end1_m = Vec3::Zero();  ///< blade end at the later sample
};

/// Axis-aligned box of a set of quads; lo > hi (empty) for no quads.
struct CutBox {
  Vec3 lo_m = Vec3::Constant(1e300);   ///< minimum corner
  Vec3 hi_m = Vec3::Constant(-1e300);  ///< maximum corner
  /// Grows the box by a quad.
  void add(const BladeQuad& q);
  /// True when the box of segment p-q overlaps this box grown by margin_m.
  bool overlaps_segment(const Vec3& p, const Vec3& q, double margin_m) const;
};

/// True when segment p->q crosses the quad (as triangles tip0-end0-end1 and tip0-end1-tip1, edges included);
/// *t (when non-null) is the smallest crossing parameter in [0, 1] along p->q. A quad whose blade did not move
/// is degenerate and is never crossed.
bool segment_crosses_quad(const Vec3& p_m, const Vec3& q_m, const BladeQuad& quad, double* t = nullptr);

/// Quads with their boxes, for many segment tests against them: the box of all, of each run of kChunk consecutive
/// quads (a stroke's quads follow the blade, so a run is compact) and of each quad. Copyable.
struct CutQuads {
  static constexpr std::size_t kChunk = 16;
  std::vector<BladeQuad> quads;   ///< the quads
  std::vector<CutBox> quad_box;   ///< box of each quad
  std::vector<CutBox> chunk_box;  ///< box of quads [kChunk i, kChunk (i + 1))
  CutBox box;                     ///< box of all
  CutQuads() = default;
  explicit CutQuads(const std::vector<BladeQuad>& q);
};

/// True when segment p->q crosses any of the quads whose box its box overlaps; *t as above over all of them, and
/// *quad (when non-null, with t) the index of the quad crossed at *t.
bool segment_crosses_any(const Vec3& p_m, const Vec3& q_m, const CutQuads& quads, double* t = nullptr,
                         std::size_t* quad = nullptr);

/// Removes every spring whose rest segment crosses a quad (in rest coordinates), updates springs_per_family and touches
/// the lattice (solver caches are rebuilt) when any was removed. Returns the number removed.
int cut_springs(Lattice* lat, const std::vector<BladeQuad>& quads);

/// cut_springs() that removes at most max_removed springs (> 0) this call and defers the rest: *deferred holds
/// the node pairs (unordered_pair_key of a and b) of crossed springs still in the lattice, oldest first. The deferred ones
/// go first, then new crossings in spring order; a spring crossed again while deferred keeps its place. The
/// springs removed keep the others' order, as cut_springs() does. Returns the number removed.
int cut_springs_capped(Lattice* lat, const std::vector<BladeQuad>& quads, int max_removed,
                       std::vector<uint64_t>* deferred);

/// Connected components of the spring graph: *label gets one id per node (0..count-1, numbered in node order);
/// a node with no spring is a component of its own. Returns the count.
int spring_components(const Lattice& lat, std::vector<int32_t>* label);

/// Number of nodes in components that hold no fixed node (pieces cut free: they move under gravity alone).
int free_nodes(const Lattice& lat);

/// Keeps free nodes at or above floor_z_m: a node below is put on it, its downward speed removed and its
/// sliding speed halved (friction). Returns the number of nodes held. Non-finite nodes are put back at rest.
int apply_floor(Lattice* lat, double floor_z_m);

}  // namespace palpate
