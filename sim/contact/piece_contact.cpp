#include "sim/contact/piece_contact.h"

#include <algorithm>
#include <cmath>

#include "sim/cut/cut.h"

namespace palpate {

void PieceContact::update(const Lattice& lat, const GridHierarchy& grid) {
  (void)grid;
  std::vector<int32_t> label;
  const int count = spring_components(lat, &label);
  std::vector<uint8_t> anchored(static_cast<std::size_t>(count), 0);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (lat.fixed[i]) anchored[label[i]] = 1;
  free_.clear();
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (!anchored[label[i]]) free_.push_back(static_cast<int32_t>(i));
  body_.assign(lat.cell_nodes.size(), 0);
  for (std::size_t s = 0; s < lat.cell_nodes.size(); ++s) {
    bool all = true;
    for (int32_t n : lat.cell_nodes[s]) all = all && anchored[label[n]];
    body_[s] = all ? 1 : 0;
  }

}

int PieceContact::apply(Lattice* lat, const GridHierarchy& grid) const {
  if (free_.empty()) return 0;
  const int level = lat->level;
  const int n = lat->cells_per_axis;
  auto slot_at = [&](const CellCoord& c) {
    if (c.i < 0 || c.j < 0 || c.k < 0 || c.i >= n || c.j >= n || c.k >= n) return int32_t{-1};
    return lat->slot_of_cell[grid.linear_index(c, level)];
  };
  int pushed = 0;
  for (int32_t node : free_) {
    Vec3& x = lat->x_m[node];
    if (!x.allFinite()) continue;
    // the body barely moves (it holds a fixed node): look its cell up at rest, test against its box as deformed
    const CellCoord c = grid.cell_of(x, level);
    const int32_t slot = slot_at(c);
    if (!body_cell(slot)) continue;
    Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
    for (int32_t m : lat->cell_nodes[slot]) {
      lo = lo.cwiseMin(lat->x_m[m]);
      hi = hi.cwiseMax(lat->x_m[m]);
    }
    // a node on the body's side face, which sags by a hair, is still over the body: a twentieth of a cell's skin
    const double skin = 0.05 * lat->cell_m;
    if (!((x.array() >= lo.array() - skin).all() && (x.array() <= hi.array() + skin).all())) continue;
    // how deep it is along each direction through the run of body cells (0 on a face: on the surface, not in it).
    // A piece falls onto the body: out against gravity when falling or less than half a cell in that way, else
    // the shallowest way out
    auto depth_along = [&](int a, int dir) {
      double depth = dir < 0 ? x[a] - lo[a] : hi[a] - x[a];
      CellCoord o = c;
      for (int more = 0; more < 3; ++more) {
        (a == 0 ? o.i : a == 1 ? o.j : o.k) += dir;
        if (!body_cell(slot_at(o))) break;
        depth += lat->cell_m;
      }
      return depth;
    };
    int best_axis = -1, best_dir = 0;
    double best = 1e300;
    const Vec3& g = lat->gravity_m_per_s2;
    if (g.squaredNorm() > 0.0) {
      int up = 0;
      g.cwiseAbs().maxCoeff(&up);
      const int dir = g[up] < 0.0 ? 1 : -1;
      const double d = depth_along(up, dir);
      if (d <= 0.0) continue;  // on or above the body's top, within the skin
      if (d < 0.5 * lat->cell_m || lat->v_m_per_s[node][up] * dir < 0.0) best = d, best_axis = up, best_dir = dir;
    }
    const bool fell = best_axis >= 0;
    for (int a = 0; a < 3 && !fell; ++a)
      for (int dir = -1; dir <= 1; dir += 2) {
        const double d = depth_along(a, dir);
        if (d <= 0.0) {
          best = 0.0;  // on the surface
          a = 3;
          break;
        }
        if (d < best) best = d, best_axis = a, best_dir = dir;
      }
    if (!(best > 0.0)) continue;
    Vec3& v = lat->v_m_per_s[node];
    x[best_axis] += best_dir * best;
    // no speed into the body; sliding speed halved
    const double vn = best_dir * v[best_axis];
    for (int a = 0; a < 3; ++a)
      if (a != best_axis) v[a] *= 0.5;
    v[best_axis] = best_dir * std::max(0.0, vn);
    ++pushed;
  }
  return pushed;
}

}  // namespace palpate
