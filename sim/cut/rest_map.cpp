#include "sim/cut/rest_map.h"

#include <algorithm>
#include <cmath>

#include "sim/lattice/deformer.h"

namespace palpate {
namespace {

// Local coordinates u of p in cell `slot` (current positions): x(u) = sum_c w_c(u) x_c solved by Newton from
// the cell's first corner as if it were undeformed. Unclamped, so a point outside gives an extrapolation.
Vec3 local_in_cell(const Lattice& lat, int32_t slot, const Vec3& p) {
  const auto& nodes = lat.cell_nodes[slot];
  Vec3 u = (p - lat.x_m[nodes[0]]) / lat.cell_m;
  for (int it = 0; it < 6; ++it) {
    Vec3 x = Vec3::Zero();
    Mat3 J = Mat3::Zero();
    for (int c = 0; c < 8; ++c) {
      const double fx = (c & 1) ? u.x() : 1.0 - u.x(), sx = (c & 1) ? 1.0 : -1.0;
      const double fy = (c & 2) ? u.y() : 1.0 - u.y(), sy = (c & 2) ? 1.0 : -1.0;
      const double fz = (c & 4) ? u.z() : 1.0 - u.z(), sz = (c & 4) ? 1.0 : -1.0;
      const Vec3& xc = lat.x_m[nodes[c]];
      x += fx * fy * fz * xc;
      J.col(0) += sx * fy * fz * xc;
      J.col(1) += fx * sy * fz * xc;
      J.col(2) += fx * fy * sz * xc;
    }
    const Vec3 r = x - p;
    if (r.squaredNorm() < 1e-24 * lat.cell_m * lat.cell_m) break;
    // a collapsed cell: keep the last estimate
    if (!(std::abs(J.determinant()) > 1e-12 * lat.cell_m * lat.cell_m * lat.cell_m)) break;
    const Vec3 du = J.partialPivLu().solve(r);
    if (!du.allFinite()) break;
    u -= du;
  }
  return u;
}

// How far u lies outside the unit cube (0 inside), the max over axes.
double outside(const Vec3& u) { return std::max({-u.minCoeff(), u.maxCoeff() - 1.0, 0.0}); }

Vec3 rest_of(const Lattice& lat, int32_t slot, const Vec3& u) {
  // a cell at rest is an axis-aligned cube: its trilinear map is affine, so extrapolation is exact
  return lat.rest_m[lat.cell_nodes[slot][0]] + lat.cell_m * u;
}

}  // namespace

Vec3 world_to_rest(const Lattice& lat, const GridHierarchy& grid, const Vec3& p_W_m) {
  if (lat.cell_nodes.empty() || !p_W_m.allFinite()) return p_W_m;
  const int level = lat.level;
  const int n = lat.cells_per_axis;
  auto slot_at = [&](const CellCoord& c) {
    if (c.i < 0 || c.j < 0 || c.k < 0 || c.i >= n || c.j >= n || c.k >= n) return int32_t{-1};
    return lat.slot_of_cell[grid.linear_index(c, level)];
  };
  // start in the cell the point is in at rest, else the region cell nearest to it within two cells
  CellCoord c = grid.cell_of(p_W_m, level);
  int32_t slot = slot_at(c);
  if (slot < 0) {
    double best = 1e300;
    const CellCoord c0 = c;
    for (int dk = -2; dk <= 2; ++dk)
      for (int dj = -2; dj <= 2; ++dj)
        for (int di = -2; di <= 2; ++di) {
          const CellCoord o{c0.i + di, c0.j + dj, c0.k + dk};
          const int32_t s = slot_at(o);
          if (s < 0) continue;
          Vec3 mid = Vec3::Zero();
          for (int32_t node : lat.cell_nodes[s]) mid += lat.x_m[node];
          const double d2 = (mid / 8.0 - p_W_m).squaredNorm();
          if (d2 < best) {
            best = d2;
            slot = s;
            c = o;
          }
        }
    if (slot < 0) return p_W_m;
  }
  // walk toward the cell whose map holds the point, keeping the best one seen
  int32_t best_slot = slot;
  Vec3 best_u = local_in_cell(lat, slot, p_W_m);
  double best_out = outside(best_u);
  Vec3 u = best_u;
  for (int step = 0; step < 6 && best_out > 1e-9; ++step) {
    int axis = 0;
    double worst = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double o = std::max(-u[a], u[a] - 1.0);
      if (o > worst) {
        worst = o;
        axis = a;
      }
    }
    CellCoord next = c;
    (axis == 0 ? next.i : axis == 1 ? next.j : next.k) += u[axis] < 0.0 ? -1 : 1;
    const int32_t s = slot_at(next);
    if (s < 0) break;
    c = next;
    u = local_in_cell(lat, s, p_W_m);
    const double o = outside(u);
    if (o < best_out) {
      best_out = o;
      best_slot = s;
      best_u = u;
    } else {
      break;
    }
  }
  return rest_of(lat, best_slot, best_u);
}

void quads_to_rest(const Lattice& lat, const GridHierarchy& grid, const std::vector<BladeQuad>& quads_W,
                   RestEdge* last, std::vector<BladeQuad>* out) {
  out->clear();
  auto map_edge = [&](const Vec3& tip, const Vec3& end, int pieces, RestEdge* e) {
    e->tip_W_m = tip;
    e->end_W_m = end;
    e->pieces = pieces;
    e->rest_m.resize(static_cast<std::size_t>(pieces) + 1);
    for (int i = 0; i <= pieces; ++i)
      e->rest_m[i] = world_to_rest(lat, grid, tip + (static_cast<double>(i) / pieces) * (end - tip));
  };
  RestEdge first;
  for (const BladeQuad& q : quads_W) {
    const double len = std::max((q.end0_m - q.tip0_m).norm(), (q.end1_m - q.tip1_m).norm());
    const int pieces = std::clamp(static_cast<int>(std::ceil(len / lat.cell_m)), 1, 256);
    const bool reuse = last->pieces == pieces && last->tip_W_m == q.tip0_m && last->end_W_m == q.end0_m;
    if (!reuse) map_edge(q.tip0_m, q.end0_m, pieces, &first);
    const std::vector<Vec3> e0 = reuse ? last->rest_m : first.rest_m;
    map_edge(q.tip1_m, q.end1_m, pieces, last);
    for (int i = 0; i < pieces; ++i) out->push_back({e0[i], e0[i + 1], last->rest_m[i], last->rest_m[i + 1]});
  }
}

}  // namespace palpate
