#include "sim/cut/cut_model.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "sim/lattice/deformer.h"
#include "sim/cut/rest_map.h"

namespace palpate {

CutModel::CutModel(const TriMesh& rest, const std::vector<VertexBinding>& bindings, const GridHierarchy* grid, int level,
                   double blade_length_m)
    : grid_(grid),
      level_(level),
      blade_length_m_(blade_length_m),
      rest_m_(rest.vertices_m),
      triangles_(rest.triangles),
      bindings_(bindings),
      blocked_(rest.vertices_m.size(), 0),
      fallback_(rest.vertices_m.size(), -1),
      tri_grid_(grid->cell_size_m(level), rest.vertices_m, rest.triangles) {
  const auto cells = static_cast<std::size_t>(grid->num_cells(level));
  cell_first_.assign(cells, -1);
  cell_count_.assign(cells, 0);
  next_in_cell_.reserve(rest_m_.size());
  for (std::size_t v = 0; v < rest_m_.size(); ++v) link_vertex(static_cast<int32_t>(v));
  normals_.reset(rest_m_.size(), triangles_);
  // the mesh starts at rest: the patch search's grid is built here, before the first frame
  box_grid_.build(rest_m_, triangles_);
  box_all_stale_ = false;
}

void CutModel::link_vertex(int32_t v) {
  const int32_t c = bindings_[static_cast<std::size_t>(v)].cell;
  next_in_cell_.push_back(cell_first_[c]);
  cell_first_[c] = v;
  ++cell_count_[c];
}

void CutModel::cells_in_box(const Vec3& lo_m, const Vec3& hi_m, std::vector<int32_t>* cells) const {
  // a point on a cell's face may be bound to either cell: a hair of margin takes both
  const Vec3 eps = Vec3::Constant(1e-9 * grid_->cell_size_m(level_));
  const CellCoord a = grid_->cell_of(lo_m - eps, level_), b = grid_->cell_of(hi_m + eps, level_);
  for (int k = a.k; k <= b.k; ++k)
    for (int j = a.j; j <= b.j; ++j)
      for (int i = a.i; i <= b.i; ++i) cells->push_back(grid_->linear_index({i, j, k}, level_));
}

void CutModel::add_sample(const Vec3& tip_m, const Vec3& axis, bool cutting) {
  if (!cutting || !tip_m.allFinite() || !axis.allFinite()) {
    have_prev_ = false;
    return;
  }
  const Vec3 end = tip_m + blade_length_m_ * axis;
  if (have_prev_ && ((tip_m - prev_tip_m_).squaredNorm() > 0.0 || (end - prev_end_m_).squaredNorm() > 0.0))
    pending_.push_back({prev_tip_m_, prev_end_m_, tip_m, end});
  prev_tip_m_ = tip_m;
  prev_end_m_ = end;
  have_prev_ = true;
}

int CutModel::springs_this_apply() const {
  // a quarter of those waiting when more than the limit's four times wait: none waits much more than four frames
  return std::max(max_springs_, static_cast<int>((deferred_.size() + 3) / 4));
}

CutReport CutModel::apply(Lattice* lat, std::vector<Vec3>* vertices_m) {
  CutReport rep = apply_quads(pending_, lat, vertices_m);
  pending_.clear();
  return rep;
}

namespace {

// The quad moved by d_m along one fixed direction, the same for every quad so those sharing an edge still share it
// (moved along each one's normal, the pieces of a bent blade would open gaps a spring or edge slips through).
BladeQuad offset_quad(const BladeQuad& q, double d_m) {
  const Vec3 d = d_m * Vec3(1.0, 0.618034, 0.381966).normalized();
  return {q.tip0_m + d, q.end0_m + d, q.tip1_m + d, q.end1_m + d};
}

}  // namespace

bool CutModel::block_corners(const Lattice& lat, std::size_t v, const Vec3& p_m, const CutQuads& quads) {
  const int32_t slot = lat.slot_of_cell[bindings_[v].cell];
  if (slot < 0) return false;
  const uint8_t before = blocked_[v];
  for (int c = 0; c < 8; ++c) {
    if (blocked_[v] & (1u << c)) continue;
    if (segment_crosses_any(p_m, lat.rest_m[lat.cell_nodes[slot][c]], quads))
      blocked_[v] |= static_cast<uint8_t>(1u << c);
  }
  return blocked_[v] != before;
}

int32_t CutModel::nearest_visible_node(const Lattice& lat, std::size_t v, const Vec3& p_m, const CutQuads& quads) const {
  const CellCoord c = grid_->coord_of(bindings_[v].cell, level_);
  const int n = lat.cells_per_axis;
  int32_t best = -1;
  double best_d2 = 1e300;
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const CellCoord o{c.i + di, c.j + dj, c.k + dk};
        if (o.i < 0 || o.j < 0 || o.k < 0 || o.i >= n || o.j >= n || o.k >= n) continue;
        const int32_t slot = lat.slot_of_cell[grid_->linear_index(o, level_)];
        if (slot < 0) continue;
        for (int32_t node : lat.cell_nodes[slot]) {
          const double d2 = (lat.rest_m[node] - p_m).squaredNorm();
          if (d2 < best_d2 && !segment_crosses_any(p_m, lat.rest_m[node], quads)) {
            best_d2 = d2;
            best = node;
          }
        }
      }
  return best;
}

CutReport CutModel::apply_quads(const std::vector<BladeQuad>& quads_W, Lattice* lat, std::vector<Vec3>* vertices_m) {
  // every test in rest coordinates, so a node's side of the cut does not drift while the object moves
  int dropped = 0;
  if (!quads_W.empty()) {
    std::vector<BladeQuad> rest;
    quads_to_rest(*lat, *grid_, quads_W, &last_edge_, &rest);
    // quads_to_rest() cuts each world quad into pieces no longer than a cell, in order; a piece whose map jumped
    // (a blade end mapped into a piece that fell away, or outside every cell) sweeps far more at rest than the
    // blade did in the world: it is dropped, not cut across the object
    const double cell = lat->cell_m;
    std::size_t r = 0;
    for (const BladeQuad& w : quads_W) {
      const double len = std::max((w.end0_m - w.tip0_m).norm(), (w.end1_m - w.tip1_m).norm());
      const int pieces = std::clamp(static_cast<int>(std::ceil(len / cell)), 1, 256);
      const double swept = std::max((w.tip1_m - w.tip0_m).norm(), (w.end1_m - w.end0_m).norm());
      for (int i = 0; i < pieces && r < rest.size(); ++i, ++r) {
        const BladeQuad& q = rest[r];
        const double rest_swept = std::max((q.tip1_m - q.tip0_m).norm(), (q.end1_m - q.end0_m).norm());
        const double rest_len = std::max((q.end0_m - q.tip0_m).norm(), (q.end1_m - q.tip1_m).norm());
        if (rest_swept > kMaxRestStretch * swept + 0.5 * cell || rest_len > kMaxRestStretch * cell) {
          ++dropped;
          continue;
        }
        queued_.push_back(offset_quad(q, kBladeOffsetCells * cell));
      }
    }
  }
  // the front of the queue, up to the work limit: the triangle entries of the cubes the quads reach and the
  // vertices of the cells they reach, each cube and cell counted once
  std::size_t take = queued_.size();
  if (max_work_ > 0 && !queued_.empty()) {
    std::unordered_set<uint64_t> seen_cubes;
    std::unordered_set<int32_t> seen_cells;
    std::vector<uint64_t> keys;
    std::vector<int32_t> cells;
    std::size_t items = 0;
    take = 0;
    while (take < queued_.size()) {
      CutBox b;
      b.add(queued_[take]);
      keys.clear();
      tri_grid_.cube_keys(b.lo_m, b.hi_m, &keys);
      for (uint64_t k : keys)
        if (seen_cubes.insert(k).second) items += tri_grid_.count_in(k);
      cells.clear();
      cells_in_box(b.lo_m, b.hi_m, &cells);
      for (int32_t c : cells)
        if (seen_cells.insert(c).second) items += static_cast<std::size_t>(cell_count_[c]);
      if (take > 0 && items > static_cast<std::size_t>(max_work_)) break;
      ++take;
    }
    // and at least a quarter of the queue, so the cut never falls more than about four applies behind the blade:
    // the limit counts every triangle and vertex of the cubes and cells a quad reaches (what their box tests cost),
    // which on a dense mesh a stroke's quads of one frame exceed many times over (a 10^6-triangle scan: 8000 counted
    // for 7 of its 270 pieces a frame); the queue then grew without end and the stroke was never cut where it went
    take = std::max(take, std::min(queued_.size(), (queued_.size() + 3) / 4));
  }
  last_batch_.assign(queued_.begin(), queued_.begin() + static_cast<std::ptrdiff_t>(take));
  queued_.erase(queued_.begin(), queued_.begin() + static_cast<std::ptrdiff_t>(take));
  const std::vector<BladeQuad>& batch = last_batch_;
  CutReport rep = cut_rest(batch, lat, vertices_m);
  rep.quads_dropped = dropped;
  rep.quads_cut = static_cast<int>(batch.size());
  return rep;
}

CutReport CutModel::cut_rest(const std::vector<BladeQuad>& quads, Lattice* lat, std::vector<Vec3>* vertices_m) {
  CutReport rep;
  if (quads.empty()) {
    if (!deferred_.empty()) rep.springs_cut = cut_springs_capped(lat, {}, springs_this_apply(), &deferred_);
    return rep;
  }
  const CutQuads set(quads);
  rep.springs_cut = max_springs_ > 0 ? cut_springs_capped(lat, quads, springs_this_apply(), &deferred_)
                                     : cut_springs(lat, quads);

  const std::size_t old_count = rest_m_.size();
  std::vector<SplitVertex> created;
  // the incision's copies stay inside the lattice's cells, so they move with it
  IncisionShape groove;
  groove.depth_m = incision_cells_ * lat->cell_m;
  groove.gap_m = incision_gap_m_;
  const Aabb cube = grid_->cube();
  groove.keep = [&](const Vec3& p) {
    if ((p.array() < cube.min_m.array()).any() || (p.array() > cube.max_m.array()).any()) return false;
    return lat->slot_of_cell[grid_->linear_index(grid_->cell_of(p, level_), level_)] >= 0;
  };
  rep.split = split_mesh(quads, &rest_m_, vertices_m, &triangles_, &created, &tips_, &tri_grid_, groove, &changes_);
  normals_.retriangulate(rest_m_.size(), changes_, triangles_);
  for (const TriangleChange& c : changes_) box_stale_.push_back(c.slot);

  // existing vertices whose cell a quad's box overlaps (a vertex's segments to its corners stay in its cell, so
  // no other can be cut off from a corner): corners now on the far side of the cut are dropped
  std::vector<int32_t> cells;
  for (const CutBox& b : set.quad_box) cells_in_box(b.lo_m, b.hi_m, &cells);
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  std::vector<int32_t> near_v;
  for (int32_t c : cells)
    for (int32_t v = cell_first_[c]; v >= 0; v = next_in_cell_[v])
      if (static_cast<std::size_t>(v) < old_count) near_v.push_back(v);
  std::sort(near_v.begin(), near_v.end());
  rep.vertices_tested = static_cast<int>(near_v.size());
  for (int32_t v : near_v)
    if (block_corners(*lat, v, rest_m_[v], set)) {
      ++rep.vertices_rebound;
      redeform_.push_back(v);
    }
  // new vertices: bound at their rest position, tested from a point just off the cut on their own side
  auto off_cut = [&](std::size_t v, int32_t from) { return Vec3(rest_m_[v] + 0.01 * (rest_m_[from] - rest_m_[v])); };
  for (std::size_t i = 0; i < created.size(); ++i) {
    const std::size_t v = old_count + i;
    const SplitVertex& sv = created[i];
    bindings_.push_back(bind_point(*grid_, level_, rest_m_[v]));
    const bool same_cell = bindings_[v].cell == bindings_[sv.from].cell;
    blocked_.push_back(same_cell ? blocked_[sv.from] : 0);
    fallback_.push_back(same_cell ? fallback_[sv.from] : -1);
    block_corners(*lat, v, off_cut(v, sv.from), set);
    link_vertex(static_cast<int32_t>(v));
    near_v.push_back(static_cast<int32_t>(v));
    redeform_.push_back(static_cast<int32_t>(v));
  }
  // vertices cut off from all their corners follow the nearest node on their side
  for (int32_t v : near_v) {
    if (blocked_[v] != 0xff || fallback_[v] >= 0) continue;
    const Vec3 p = static_cast<std::size_t>(v) < old_count ? rest_m_[v] : off_cut(v, created[v - old_count].from);
    fallback_[v] = nearest_visible_node(*lat, v, p, set);
    if (fallback_[v] < 0) continue;
    fallback_users_.push_back(v);
    redeform_.push_back(v);
  }
  return rep;
}

Vec3 CutModel::deformed(const Lattice& lat, std::size_t v, bool* orphan) const {
  *orphan = false;
  const int32_t slot = lat.slot_of_cell[bindings_[v].cell];
  if (slot < 0) return rest_m_[v];
  const auto& nodes = lat.cell_nodes[slot];
  const auto w = trilinear_weights(bindings_[v].local);
  const uint8_t mask = blocked_[v];
  // renormalised trilinear weights over the corners on the vertex's side
  Vec3 d = Vec3::Zero();
  double sum = 0.0;
  int open = 0;
  for (int c = 0; c < 8; ++c) {
    if (mask & (1u << c)) continue;
    d += w[c] * (lat.x_m[nodes[c]] - lat.rest_m[nodes[c]]);
    sum += w[c];
    ++open;
  }
  if (sum > 1e-6) return rest_m_[v] + d / sum;
  // on a face or edge away from its side's corners: equal weights over them, else the fallback node
  *orphan = true;
  d.setZero();
  if (open > 0) {
    for (int c = 0; c < 8; ++c)
      if (!(mask & (1u << c))) d += lat.x_m[nodes[c]] - lat.rest_m[nodes[c]];
    d /= open;
  } else if (fallback_[v] >= 0) {
    d = lat.x_m[fallback_[v]] - lat.rest_m[fallback_[v]];
  }
  return rest_m_[v] + d;
}

void CutModel::deform(const Lattice& lat, std::vector<Vec3>* vertices_m) const {
  orphans_ = 0;
  // the patch search's grid holds the boxes of the positions before: the triangles of those that change move
  box_all_stale_ = box_all_stale_ || vertices_m->size() != rest_m_.size();
  vertices_m->resize(rest_m_.size());
  bool orphan = false;
  for (std::size_t v = 0; v < rest_m_.size(); ++v) {
    const Vec3 p = deformed(lat, v, &orphan);
    if (!box_all_stale_ && p != (*vertices_m)[v]) box_moved(static_cast<int32_t>(v));
    (*vertices_m)[v] = p;
    orphans_ += orphan ? 1 : 0;
  }
}

std::size_t CutModel::deform_changed(const Lattice& lat, std::vector<Vec3>* vertices_m) {
  if (x_deformed_m_.size() != lat.x_m.size()) {
    // the first call: every vertex, and every normal
    deform(lat, vertices_m);
    normals_.invalidate();
    x_deformed_m_ = lat.x_m;
    redeform_.clear();
    return rest_m_.size();
  }
  vertices_m->resize(rest_m_.size());
  // the vertices of every cell with a node that moved since the last call (the others compute what they hold)
  node_moved_.assign(lat.x_m.size(), 0);
  bool any = false;
  for (std::size_t i = 0; i < lat.x_m.size(); ++i)
    if (lat.x_m[i] != x_deformed_m_[i]) {
      node_moved_[i] = 1;
      x_deformed_m_[i] = lat.x_m[i];
      any = true;
    }
  if (any) {
    for (std::size_t s = 0; s < lat.cells.size(); ++s)
      for (int32_t node : lat.cell_nodes[s])
        if (node_moved_[static_cast<std::size_t>(node)]) {
          vertices_in_cell(lat.cells[s], &redeform_);
          break;
        }
    for (int32_t v : fallback_users_)
      if (blocked_[v] == 0xff && node_moved_[static_cast<std::size_t>(fallback_[v])]) redeform_.push_back(v);
  }
  std::sort(redeform_.begin(), redeform_.end());
  redeform_.erase(std::unique(redeform_.begin(), redeform_.end()), redeform_.end());
  bool orphan = false;
  for (int32_t v : redeform_) {
    const Vec3 p = deformed(lat, static_cast<std::size_t>(v), &orphan);
    if (p == (*vertices_m)[v]) continue;
    (*vertices_m)[v] = p;
    normals_.moved(v);
    box_moved(v);
  }
  const std::size_t done = redeform_.size();
  redeform_.clear();
  return done;
}

void CutModel::box_moved(int32_t v) const {
  const auto& tris = normals_.triangles_of(v);
  box_stale_.insert(box_stale_.end(), tris.begin(), tris.end());
}

void CutModel::triangles_in_box(const std::vector<Vec3>& vertices_m, const Vec3& lo_m, const Vec3& hi_m,
                                std::vector<int32_t>* out) const {
  // the grid follows what changed since the last call; built again when most of it did (or the mesh shrank)
  if (box_all_stale_ || box_grid_.size() > triangles_.size() || 4 * box_stale_.size() > triangles_.size()) {
    box_grid_.build(vertices_m, triangles_);
  } else {
    // the slots appended, in order, then those rewritten or moved
    for (auto t = static_cast<int32_t>(box_grid_.size()); t < static_cast<int32_t>(triangles_.size()); ++t)
      box_grid_.update(t, vertices_m, triangles_);
    std::sort(box_stale_.begin(), box_stale_.end());
    box_stale_.erase(std::unique(box_stale_.begin(), box_stale_.end()), box_stale_.end());
    for (int32_t t : box_stale_) box_grid_.update(t, vertices_m, triangles_);
  }
  box_stale_.clear();
  box_all_stale_ = false;
  box_grid_.query(vertices_m, triangles_, lo_m, hi_m, out);
}

}  // namespace palpate
