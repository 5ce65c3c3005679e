#include "sim/lattice/refined_lattice.h"

#include <algorithm>
#include <bit>
#include <string>
#include <unordered_map>

#include "sim/lattice/deformer.h"
#include "sim/lattice/hanging.h"
#include "sim/material/material.h"
#include "sim/material/spring_builder.h"

namespace palpate {
namespace {

// Grid vertex (i, j, k) at a level with nv vertices per axis, as a linear index.
int32_t vertex_index(const CellCoord& g, int nv) { return g.i + nv * (g.j + nv * g.k); }

// The range of coarse cells (per axis) whose closed box holds fine vertex coordinate g: two where g lies on a coarse
// plane, one otherwise; clipped to [0, n).
void coarse_range(int g, int r, int n, int* lo, int* hi) {
  *lo = g % r == 0 ? g / r - 1 : g / r;
  *hi = g / r;
  *lo = std::max(*lo, 0);
  *hi = std::min(*hi, n - 1);
}

}  // namespace

Result<Lattice> build_refined_lattice(const GridHierarchy& grid, const LatticeSpec& spec,
                                      const std::vector<int32_t>& coarse_cells, int fine_level,
                                      const std::vector<int32_t>& refine) {
  if (fine_level <= spec.level || fine_level > grid.levels())
    return make_error("refined lattice: fine level ", std::to_string(fine_level), " is not between lattice level ",
                      std::to_string(spec.level + 1), " and grid level ", std::to_string(grid.levels()));
  return build_refined_lattice(grid, spec, coarse_cells, fine_level, split_leaves(grid, spec.level, coarse_cells, fine_level, refine));
}

Result<Lattice> build_refined_lattice(const GridHierarchy& grid, const LatticeSpec& spec,
                                      const std::vector<int32_t>& coarse_cells, int fine_level,
                                      const std::vector<LeafCell>& leaves) {
  const int lc = spec.level, lf = fine_level;
  if (coarse_cells.empty()) return make_error("refined lattice: no solid cells in the region at level ", std::to_string(lc));
  if (lf <= lc || lf > grid.levels())
    return make_error("refined lattice: fine level ", std::to_string(lf), " is not between lattice level ",
                      std::to_string(lc + 1), " and grid level ", std::to_string(grid.levels()));
  if (!spec.material.enabled)
    return make_error("refined lattice: needs a material (each cell's springs are calibrated at its own edge)");
  for (const LeafCell& c : leaves)
    if (c.level < lc || c.level > lf)
      return make_error("refined lattice: a cell at level ", std::to_string(c.level), " is not between levels ",
                        std::to_string(lc), " and ", std::to_string(lf));
  const int r = 1 << (lf - lc);
  const int nc = grid.cells_per_axis(lc), nf = grid.cells_per_axis(lf), nv = nf + 1;
  Lattice lat;
  lat.level = lf;
  lat.cells_per_axis = nf;
  lat.cell_m = grid.cell_size_m(lf);
  // each level's calibration (its cells' edge)
  std::vector<LatticeCalibration> cal;
  for (int l = 0; l <= lf; ++l) cal.push_back(calibrate_lattice(spec.material, grid.cell_size_m(std::max(l, 1))));
  // one damping coefficient serves every spring: the fine cells' (the coarser ones are then damped less; the rest
  // state does not depend on it)
  lat.damping_Ns_per_m = cal[static_cast<std::size_t>(lf)].damping_Ns_per_m;
  // the cells' volume or Neo-Hookean moduli do not depend on the edge (each cell's term takes its own: cell_span)
  lat.volume_Pa = cal[static_cast<std::size_t>(lf)].volume_Pa;
  lat.neo_mu_Pa = cal[static_cast<std::size_t>(lf)].neo_mu_Pa;
  lat.neo_lambda_Pa = cal[static_cast<std::size_t>(lf)].neo_lambda_Pa;
  lat.gravity_m_per_s2 = spec.gravity_m_per_s2;
  lat.slot_of_cell.assign(static_cast<std::size_t>(grid.num_cells(lf)), -1);
  std::vector<uint8_t> in_region(static_cast<std::size_t>(grid.num_cells(lc)), 0);
  for (int32_t c : coarse_cells) in_region[static_cast<std::size_t>(c)] = 1;

  // nodes at fine grid vertices, in first-seen order; each cell's corners
  std::vector<int32_t> node_of_gv(static_cast<std::size_t>(nv) * nv * nv, -1);
  std::vector<CellCoord> node_g;
  const Vec3 origin = grid.cube().min_m;
  auto node_at = [&](const CellCoord& g) {
    int32_t& id = node_of_gv[static_cast<std::size_t>(vertex_index(g, nv))];
    if (id < 0) {
      id = static_cast<int32_t>(lat.rest_m.size());
      lat.rest_m.push_back(origin + lat.cell_m * Vec3(g.i, g.j, g.k));
      lat.grid_node.push_back(vertex_index(g, nv));
      node_g.push_back(g);
    }
    return id;
  };
  std::vector<double> cell_share_kg;  // each cell's solid mass over 8 (n_c)
  const double rho = spec.material.density_kg_per_m3;
  for (const LeafCell& leaf : leaves) {
    // the leaf's slot covers every fine cell under it, so a fine-level lookup finds it
    const int span = 1 << (lf - leaf.level);
    const CellCoord c = grid.coord_of(leaf.index, leaf.level);
    const CellCoord g0{c.i * span, c.j * span, c.k * span};
    const double l = grid.cell_size_m(leaf.level);
    const auto slot = static_cast<int32_t>(lat.cells.size());
    lat.cells.push_back(grid.linear_index(g0, lf));
    lat.cell_span.push_back(span);
    std::array<int32_t, 8> corners{};
    for (int corner = 0; corner < 8; ++corner)
      corners[corner] = node_at({g0.i + span * (corner & 1), g0.j + span * ((corner >> 1) & 1), g0.k + span * ((corner >> 2) & 1)});
    lat.cell_nodes.push_back(corners);
    cell_share_kg.push_back(rho * l * l * l * cell_solid_fraction(grid, leaf.index, leaf.level) / 8.0);
    for (int dk = 0; dk < span; ++dk)
      for (int dj = 0; dj < span; ++dj)
        for (int di = 0; di < span; ++di)
          lat.slot_of_cell[static_cast<std::size_t>(grid.linear_index({g0.i + di, g0.j + dj, g0.k + dk}, lf))] = slot;
  }
  if (lat.cells.empty()) return make_error("refined lattice: no solid cells in the region at level ", std::to_string(lc));
  const std::size_t num = lat.rest_m.size();
  lat.x_m = lat.rest_m;
  lat.v_m_per_s.assign(num, Vec3::Zero());
  lat.mass_kg.assign(num, 0.0);
  for (std::size_t s = 0; s < lat.cells.size(); ++s)
    for (int32_t node : lat.cell_nodes[s]) lat.mass_kg[static_cast<std::size_t>(node)] += cell_share_kg[s];
  for (double& m : lat.mass_kg) m = std::max(m, kMinNodeMassShare * rho * lat.cell_m * lat.cell_m * lat.cell_m);

  // border: a node on the closed box of a solid coarse cell outside the region is held at rest; with fix_floor the
  // model's lowest coarse node plane too
  int min_k = nc;
  for (int64_t idx = 0; idx < grid.num_cells(lc); ++idx)
    if (grid.solid_cell(static_cast<int32_t>(idx), lc)) min_k = std::min(min_k, grid.coord_of(static_cast<int32_t>(idx), lc).k);
  lat.fixed.assign(num, 0);
  for (std::size_t i = 0; i < num; ++i) {
    const CellCoord g = node_g[i];
    int lo[3], hi[3];
    coarse_range(g.i, r, nc, &lo[0], &hi[0]);
    coarse_range(g.j, r, nc, &lo[1], &hi[1]);
    coarse_range(g.k, r, nc, &lo[2], &hi[2]);
    for (int k = lo[2]; k <= hi[2] && !lat.fixed[i]; ++k)
      for (int j = lo[1]; j <= hi[1] && !lat.fixed[i]; ++j)
        for (int ii = lo[0]; ii <= hi[0] && !lat.fixed[i]; ++ii) {
          const int32_t idx = grid.linear_index({ii, j, k}, lc);
          if (grid.solid_cell(idx, lc) && !in_region[static_cast<std::size_t>(idx)]) lat.fixed[i] = 1;
        }
    if (spec.fix_floor && g.k == min_k * r) lat.fixed[i] = 1;
  }

  // hanging: a free node on the closed box of a coarser cell but not at its corners moves with that cell's face or
  // edge (the coarsest such cell: a finer one's face lies in it). Listed coarsest cell first, so a node hanging on a
  // cell whose corners hang themselves comes after them: spread_hanging in list order and fold_hanging in reverse
  // are exact.
  std::vector<std::vector<HangingNode>> by_level(static_cast<std::size_t>(lf + 1));
  for (std::size_t i = 0; i < num; ++i) {
    const CellCoord g = node_g[i];
    if (lat.fixed[i]) continue;
    bool found = false;
    for (int level = lc; level < lf && !found; ++level) {
      const int s = 1 << (lf - level);
      if (g.i % s == 0 && g.j % s == 0 && g.k % s == 0) break;  // a corner at this level is one at every finer level
      int lo[3], hi[3];
      const int n = grid.cells_per_axis(level);
      coarse_range(g.i, s, n, &lo[0], &hi[0]);
      coarse_range(g.j, s, n, &lo[1], &hi[1]);
      coarse_range(g.k, s, n, &lo[2], &hi[2]);
      for (int k = lo[2]; k <= hi[2] && !found; ++k)
        for (int j = lo[1]; j <= hi[1] && !found; ++j)
          for (int ii = lo[0]; ii <= hi[0] && !found; ++ii) {
            const int32_t slot = lat.slot_of_cell[static_cast<std::size_t>(grid.linear_index({ii * s, j * s, k * s}, lf))];
            if (slot < 0 || lat.cell_span[static_cast<std::size_t>(slot)] != s) continue;  // not a leaf at this level
            const Vec3 local = Vec3(g.i - ii * s, g.j - j * s, g.k - k * s) / s;
            const auto w = trilinear_weights(local);
            HangingNode h;
            h.node = static_cast<int32_t>(i);
            for (int corner = 0; corner < 8; ++corner) {
              if (!(w[corner] > 1e-12)) continue;
              h.master[static_cast<std::size_t>(h.count)] = lat.cell_nodes[static_cast<std::size_t>(slot)][corner];
              h.weight[static_cast<std::size_t>(h.count)] = w[corner];
              ++h.count;
            }
            by_level[static_cast<std::size_t>(level)].push_back(h);
            found = true;
          }
    }
  }
  for (const auto& hs : by_level) lat.hanging.insert(lat.hanging.end(), hs.begin(), hs.end());

  // springs: each cell its own level's calibration
  SpringBuilder b{&lat, {}, true, {}};
  for (std::size_t s = 0; s < lat.cells.size(); ++s) {
    const int level = lf - std::countr_zero(static_cast<unsigned>(lat.cell_span[s]));
    const LatticeCalibration& c = cal[static_cast<std::size_t>(level)];
    b.add_cell(lat.cell_nodes[s], c.edge_N_per_m, c.diagonal_N_per_m);
  }
  lat.touch();
  return lat;
}

std::vector<int32_t> cells_near(const GridHierarchy& grid, int level, const std::vector<int32_t>& cells, const Vec3& p_m,
                                double radius_m) {
  std::vector<int32_t> out;
  const double l = grid.cell_size_m(level);
  const Vec3 origin = grid.cube().min_m;
  for (int32_t c : cells) {
    const CellCoord cc = grid.coord_of(c, level);
    const Vec3 lo = origin + l * Vec3(cc.i, cc.j, cc.k);
    const Vec3 nearest = p_m.cwiseMax(lo).cwiseMin(lo + Vec3::Constant(l));
    if ((nearest - p_m).norm() < radius_m) out.push_back(c);
  }
  return out;
}

std::vector<int32_t> deformed_coarse_cells(const GridHierarchy& grid, const Lattice& lat, int coarse_level, double keep_m) {
  std::vector<int32_t> out;
  const int r = 1 << std::max(0, lat.level - coarse_level);
  for (std::size_t s = 0; s < lat.cells.size(); ++s) {
    bool deformed = false;
    for (int32_t node : lat.cell_nodes[s])
      deformed = deformed || (lat.x_m[node] - lat.rest_m[node]).norm() > keep_m || lat.v_m_per_s[node].norm() > keep_m;
    if (!deformed) continue;
    const CellCoord f = grid.coord_of(lat.cells[s], lat.level);
    out.push_back(grid.linear_index({f.i / r, f.j / r, f.k / r}, coarse_level));
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

int carry_state_refined(const GridHierarchy& grid, const Lattice& from, Lattice* to) {
  std::unordered_map<int32_t, int32_t> index;
  index.reserve(from.num_nodes());
  for (std::size_t i = 0; i < from.num_nodes(); ++i) index.emplace(from.grid_node[i], static_cast<int32_t>(i));
  const int nf = to->cells_per_axis, nv = nf + 1;
  int carried = 0;
  for (std::size_t i = 0; i < to->num_nodes(); ++i) {
    if (to->fixed[i]) continue;
    const auto it = index.find(to->grid_node[i]);
    if (it != index.end()) {
      to->x_m[i] = from.x_m[static_cast<std::size_t>(it->second)];
      to->v_m_per_s[i] = from.v_m_per_s[static_cast<std::size_t>(it->second)];
      ++carried;
      continue;
    }
    if (from.level != to->level) continue;
    // a node new to the lattice: the old lattice's field at its rest point, from a cell of the old lattice around it
    const int32_t gv = to->grid_node[i];
    const CellCoord g{gv % nv, (gv / nv) % nv, gv / (nv * nv)};
    for (int corner = 0; corner < 8; ++corner) {
      const CellCoord c{g.i - (corner & 1), g.j - ((corner >> 1) & 1), g.k - ((corner >> 2) & 1)};
      if (c.i < 0 || c.j < 0 || c.k < 0 || c.i >= nf || c.j >= nf || c.k >= nf) continue;
      const int32_t slot = from.slot_of_cell[static_cast<std::size_t>(grid.linear_index(c, to->level))];
      if (slot < 0) continue;
      const auto w = trilinear_weights(from.local_in_cell(static_cast<std::size_t>(slot), to->rest_m[i]));
      Vec3 d = Vec3::Zero(), v = Vec3::Zero();
      for (int k = 0; k < 8; ++k) {
        const auto n = static_cast<std::size_t>(from.cell_nodes[static_cast<std::size_t>(slot)][k]);
        d += w[k] * (from.x_m[n] - from.rest_m[n]);
        v += w[k] * from.v_m_per_s[n];
      }
      to->x_m[i] = to->rest_m[i] + d;
      to->v_m_per_s[i] = v;
      ++carried;
      break;
    }
  }
  spread_hanging(*to, &to->x_m);
  spread_hanging(*to, &to->v_m_per_s);
  return carried;
}

}  // namespace palpate
