#include "runtime/session/cut_redraw.h"

#include <algorithm>
#include <cmath>

namespace palpate {

CutRedraw::CutRedraw(const Lattice& lat, int64_t num_cells, double tolerance_m)
    : tolerance_m_(tolerance_m), moving_cell_(static_cast<std::size_t>(num_cells), 0), x_layer_m_(lat.x_m) {}

void CutRedraw::mark(const Lattice& lat, const std::vector<int32_t>& cells, int grow) {
  const int n = lat.cells_per_axis;
  for (int32_t c : cells) {
    const int i = c % n, j = (c / n) % n, k = c / (n * n);
    for (int dk = -grow; dk <= grow; ++dk)
      for (int dj = -grow; dj <= grow; ++dj)
        for (int di = -grow; di <= grow; ++di) {
          const int a = i + di, b = j + dj, d = k + dk;
          if (a < 0 || b < 0 || d < 0 || a >= n || b >= n || d >= n) continue;
          const int32_t o = a + n * (b + n * d);
          if (moving_cell_[static_cast<std::size_t>(o)]) continue;
          moving_cell_[static_cast<std::size_t>(o)] = 1;
          cells_.push_back(o);
        }
  }
}

void CutRedraw::collect(const Lattice& lat, const CutModel& cut) {
  moving_.clear();
  std::vector<Vec3> lo, hi;
  lo.reserve(cells_.size());
  hi.reserve(cells_.size());
  // a cell's box from its corner nodes at rest (cells outside the lattice: from their neighbours' spacing)
  for (int32_t c : cells_) {
    cut.vertices_in_cell(c, &moving_);
    const int32_t slot = lat.slot_of_cell[static_cast<std::size_t>(c)];
    if (slot < 0) continue;
    const auto& nodes = lat.cell_nodes[static_cast<std::size_t>(slot)];
    lo.push_back(lat.rest_m[nodes[0]]);
    hi.push_back(lat.rest_m[nodes[7]]);
  }
  std::vector<int32_t> tris;
  cut.triangle_grid().query_all(lo, hi, 0.0, &tris);
  for (int32_t t : tris)
    for (int32_t v : cut.triangles()[static_cast<std::size_t>(t)]) moving_.push_back(v);
  std::sort(moving_.begin(), moving_.end());
  moving_.erase(std::unique(moving_.begin(), moving_.end()), moving_.end());
}

void CutRedraw::edge_cells(const Lattice& lat, const CutModel& cut, const Vec3& tip_m, const Vec3& end_m) {
  const Vec3 reach = Vec3::Constant(lat.cell_m);
  const int points = 1 + std::min(4096, static_cast<int>(std::ceil((end_m - tip_m).norm() / (0.5 * lat.cell_m))));
  for (int i = 0; i <= points; ++i) {
    const Vec3 p = tip_m + (static_cast<double>(i) / points) * (end_m - tip_m);
    cut.cells_in_box(p - reach, p + reach, &need_);
  }
}

void CutRedraw::restart(const Lattice& lat, const CutModel& cut, bool cutting, const Vec3& tip_m,
                        const Vec3& end_m) {
  // the cells of the old part leave it unless something below brings them back
  for (int32_t c : cells_) moving_cell_[static_cast<std::size_t>(c)] = 0;
  cells_.clear();
  // every cell with a node that moved since the layer was drawn, and the cells this frame cut in
  need_.clear();
  const double tol2 = tolerance_m_ * tolerance_m_;
  for (std::size_t s = 0; s < lat.cells.size(); ++s)
    for (int32_t node : lat.cell_nodes[s])
      if ((lat.x_m[node] - x_layer_m_[node]).squaredNorm() > tol2) {
        need_.push_back(lat.cells[s]);
        break;
      }
  for (const BladeQuad& q : cut.last_quads()) {
    CutBox b;
    b.add(q);
    cut.cells_in_box(b.lo_m, b.hi_m, &need_);
  }
  mark(lat, need_, 1);
  if (!cutting || !tip_m.allFinite() || !end_m.allFinite()) return;
  // the edge where it is and where it goes at its mean speed of the last frames, stations half a cell apart
  Vec3 step_m = Vec3::Zero();
  const int64_t n = std::min<int64_t>(tip_count_ - 1, kBladeSpeedFrames);
  constexpr int64_t kRing = kBladeSpeedFrames + 1;
  if (n > 0) step_m = (tips_m_[(tip_count_ - 1) % kRing] - tips_m_[(tip_count_ - 1 - n) % kRing]) / static_cast<double>(n);
  const Vec3 lead_m = static_cast<double>(kBladeLeadFrames) * step_m;
  const int stations = 1 + std::min(64, static_cast<int>(std::ceil(lead_m.norm() / (0.5 * lat.cell_m))));
  need_.clear();
  for (int k = 0; k <= stations; ++k) {
    const Vec3 offset_m = (static_cast<double>(k) / stations) * lead_m;
    edge_cells(lat, cut, tip_m + offset_m, end_m + offset_m);
  }
  std::sort(need_.begin(), need_.end());
  need_.erase(std::unique(need_.begin(), need_.end()), need_.end());
  mark(lat, need_, kBladeReachCells);
}

void CutRedraw::update(const Lattice& lat, const CutModel& cut, bool cutting, const Vec3& tip_m, const Vec3& end_m,
                       bool topology_changed, std::size_t first_new) {
  if (tip_m.allFinite()) tips_m_[tip_count_++ % (kBladeSpeedFrames + 1)] = tip_m;
  need_.clear();
  // cells with a node that moved since the layer was drawn
  const double tol2 = tolerance_m_ * tolerance_m_;
  for (std::size_t s = 0; s < lat.cells.size(); ++s) {
    const int32_t c = lat.cells[s];
    if (moving_cell_[static_cast<std::size_t>(c)]) continue;
    for (int32_t node : lat.cell_nodes[s])
      if ((lat.x_m[node] - x_layer_m_[node]).squaredNorm() > tol2) {
        need_.push_back(c);
        break;
      }
  }
  bool grow = !need_.empty();
  // the quads this frame cut with must have lain in the moving part (else the layer holds triangles now split)
  need_.clear();
  for (const BladeQuad& q : cut.last_quads()) {
    CutBox b;
    b.add(q);
    cut.cells_in_box(b.lo_m, b.hi_m, &need_);
  }
  for (int32_t c : need_) grow = grow || !moving_cell_[static_cast<std::size_t>(c)];
  // the cells within a cell of the blade's edge, which it cuts next
  if (cutting && tip_m.allFinite() && end_m.allFinite()) {
    need_.clear();
    edge_cells(lat, cut, tip_m, end_m);
    for (int32_t c : need_) grow = grow || !moving_cell_[static_cast<std::size_t>(c)];
  }
  if (grow) {
    restart(lat, cut, cutting, tip_m, end_m);
    previous_.swap(moving_);
    collect(lat, cut);
    // the same vertices (e.g. the blade's reach still in the air): the layer drawn for them stays
    if (moving_ != previous_) {
      x_layer_m_ = lat.x_m;
      ++layer_epoch_;
    }
  } else if (topology_changed) {
    // the split's new vertices lie on triangles the quads crossed, all in the moving part: they move too
    const std::size_t n_v = cut.rest_vertices_m().size();
    for (std::size_t v = first_new; v < n_v; ++v) moving_.push_back(static_cast<int32_t>(v));
  }
  if (topology_changed) ++topology_epoch_;
}

}  // namespace palpate
