#include "sim/lattice/lattice.h"

#include "core/pair_key.h"
#include "sim/material/material.h"
#include "sim/material/spring_builder.h"

#include <algorithm>
#include <atomic>
#include <unordered_map>
#include <unordered_set>

namespace palpate {

void Lattice::touch() {
  // process-wide counter: two lattices never share a revision, so a workspace cannot confuse them
  static std::atomic<uint64_t> counter{0};
  revision = ++counter;
}

void Lattice::reset_to_rest() {
  x_m = rest_m;
  std::fill(v_m_per_s.begin(), v_m_per_s.end(), Vec3::Zero());
}

std::vector<int32_t> region_cells(const GridHierarchy& grid, int level, const CellCoord& center, int radius_cells) {
  std::vector<int32_t> out;
  const int n = grid.cells_per_axis(level);
  for (int k = std::max(0, center.k - radius_cells); k <= std::min(n - 1, center.k + radius_cells); ++k)
    for (int j = std::max(0, center.j - radius_cells); j <= std::min(n - 1, center.j + radius_cells); ++j)
      for (int i = std::max(0, center.i - radius_cells); i <= std::min(n - 1, center.i + radius_cells); ++i) {
        const int32_t idx = grid.linear_index({i, j, k}, level);
        if (grid.solid_cell(idx, level)) out.push_back(idx);
      }
  return out;
}

Result<Lattice> build_lattice(const GridHierarchy& grid, const LatticeSpec& spec, const std::vector<int32_t>& cells) {
  if (cells.empty()) return make_error("lattice: no solid cells in the region at level ", std::to_string(spec.level));
  Lattice lat;
  const int level = spec.level;
  const int n = grid.cells_per_axis(level);
  const int nv = n + 1;  // grid nodes per axis
  lat.level = level;
  lat.cells_per_axis = n;
  lat.cell_m = grid.cell_size_m(level);
  // spring constants and damping: the raw keys, or the material's calibration at this cell size
  double k_structural = spec.structural_N_per_m, k_shear = spec.shear_N_per_m, k_bend = spec.bend_N_per_m;
  lat.damping_Ns_per_m = spec.damping_Ns_per_m;
  if (spec.material.enabled) {
    const LatticeCalibration cal = calibrate_lattice(spec.material, lat.cell_m);
    k_structural = cal.edge_N_per_m;
    k_shear = cal.diagonal_N_per_m;
    k_bend = 0.0;
    lat.damping_Ns_per_m = cal.damping_Ns_per_m;
    lat.volume_Pa = cal.volume_Pa;
    lat.neo_mu_Pa = cal.neo_mu_Pa;
    lat.neo_lambda_Pa = cal.neo_lambda_Pa;
  }
  lat.gravity_m_per_s2 = spec.gravity_m_per_s2;
  lat.cells = cells;
  lat.slot_of_cell.assign(static_cast<std::size_t>(grid.num_cells(level)), -1);

  // nodes: one per distinct grid corner of the region cells, in first-seen order
  std::vector<int32_t> node_of_gv(static_cast<std::size_t>(nv) * nv * nv, -1);
  std::vector<CellCoord> node_coord;
  const Vec3 origin = grid.cube().min_m;
  for (std::size_t s = 0; s < cells.size(); ++s) {
    lat.slot_of_cell[cells[s]] = static_cast<int32_t>(s);
    const CellCoord c = grid.coord_of(cells[s], level);
    std::array<int32_t, 8> corners{};
    for (int corner = 0; corner < 8; ++corner) {
      const CellCoord g{c.i + (corner & 1), c.j + ((corner >> 1) & 1), c.k + ((corner >> 2) & 1)};
      int32_t& id = node_of_gv[static_cast<std::size_t>(g.i + nv * (g.j + nv * g.k))];
      if (id < 0) {
        id = static_cast<int32_t>(lat.rest_m.size());
        lat.rest_m.push_back(origin + lat.cell_m * Vec3(g.i, g.j, g.k));
        lat.grid_node.push_back(g.i + nv * (g.j + nv * g.k));
        node_coord.push_back(g);
      }
      corners[corner] = id;
    }
    lat.cell_nodes.push_back(corners);
  }
  const std::size_t num = lat.rest_m.size();
  lat.x_m = lat.rest_m;
  lat.v_m_per_s.assign(num, Vec3::Zero());
  lat.mass_kg.assign(num, spec.node_mass_kg);
  if (spec.material.enabled) {
    // each cell gives 1/8 of its solid mass to each corner
    std::fill(lat.mass_kg.begin(), lat.mass_kg.end(), 0.0);
    const double cell_kg = spec.material.density_kg_per_m3 * lat.cell_m * lat.cell_m * lat.cell_m;
    for (std::size_t s = 0; s < cells.size(); ++s) {
      const double share_kg = cell_kg * cell_solid_fraction(grid, cells[s], level) / 8.0;
      for (int32_t node : lat.cell_nodes[s]) lat.mass_kg[static_cast<std::size_t>(node)] += share_kg;
    }
    // a node whose cells the solid-fraction sampling found (nearly) empty would be massless: no explicit step is
    // stable for it and the inertial terms divide by its mass. It keeps kMinNodeMassShare of a cell, an eighth of
    // a full corner's share (mass scaling at the surface: it lowers only such a node's frequency, by at most
    // sqrt(8) against a full corner)
    for (double& m : lat.mass_kg) m = std::max(m, kMinNodeMassShare * cell_kg);
  }
  lat.fixed.assign(num, 0);

  // border: a node touching a solid cell that is not in the region is held at rest
  int min_k = n;
  for (int64_t idx = 0; idx < grid.num_cells(level); ++idx)
    if (grid.solid_cell(static_cast<int32_t>(idx), level)) min_k = std::min(min_k, grid.coord_of(static_cast<int32_t>(idx), level).k);
  for (std::size_t i = 0; i < num; ++i) {
    const CellCoord g = node_coord[i];
    for (int corner = 0; corner < 8 && !lat.fixed[i]; ++corner) {
      const CellCoord c{g.i - (corner & 1), g.j - ((corner >> 1) & 1), g.k - ((corner >> 2) & 1)};
      if (c.i < 0 || c.j < 0 || c.k < 0 || c.i >= n || c.j >= n || c.k >= n) continue;
      const int32_t idx = grid.linear_index(c, level);
      if (grid.solid_cell(idx, level) && lat.slot_of_cell[idx] < 0) lat.fixed[i] = 1;
    }
    if (spec.fix_floor && g.k == min_k) lat.fixed[i] = 1;
  }

  SpringBuilder b{&lat, {}, spec.material.enabled, {}};
  auto node_at = [&](int i, int j, int k) -> int32_t {
    if (i < 0 || j < 0 || k < 0 || i >= nv || j >= nv || k >= nv) return -1;
    return node_of_gv[static_cast<std::size_t>(i + nv * (j + nv * k))];
  };
  // structural: the 12 cell edges
  if (k_structural > 0.0 || k_bend > 0.0) {
    for (const auto& cn : lat.cell_nodes)
      for (int corner = 0; corner < 8; ++corner)
        for (int axis = 0; axis < 3; ++axis)
          if (!(corner & (1 << axis))) {
            const int32_t a = cn[corner], o = cn[corner | (1 << axis)];
            if (k_structural > 0.0) b.add(a, o, k_structural, SpringFamily::kStructural);
            else b.seen.insert(unordered_pair_key(a, o));  // bend still needs to know the edge exists
          }
  }
  std::unordered_set<uint64_t> edges = b.seen;  // structural edges, for the bend rule below
  if (k_shear > 0.0) {
    for (const auto& cn : lat.cell_nodes) {
      // face diagonals: for each axis pair, both diagonals of the two faces normal to the third axis
      for (int normal = 0; normal < 3; ++normal) {
        const int u = 1 << ((normal + 1) % 3), w = 1 << ((normal + 2) % 3);
        for (int side = 0; side < 2; ++side) {
          const int base = side ? (1 << normal) : 0;
          b.add(cn[base], cn[base | u | w], k_shear, SpringFamily::kShear);
          b.add(cn[base | u], cn[base | w], k_shear, SpringFamily::kShear);
        }
      }
      // body diagonals
      for (int corner = 0; corner < 4; ++corner) b.add(cn[corner], cn[7 - corner], k_shear, SpringFamily::kShear);
    }
  }
  if (k_bend > 0.0) {
    for (std::size_t i = 0; i < num; ++i) {
      const CellCoord g = node_coord[i];
      for (int axis = 0; axis < 3; ++axis) {
        const int di = axis == 0, dj = axis == 1, dk = axis == 2;
        const int32_t mid = node_at(g.i + di, g.j + dj, g.k + dk);
        const int32_t far = node_at(g.i + 2 * di, g.j + 2 * dj, g.k + 2 * dk);
        if (mid < 0 || far < 0) continue;
        const int32_t self = static_cast<int32_t>(i);
        if (edges.count(unordered_pair_key(self, mid)) && edges.count(unordered_pair_key(mid, far)))
          b.add(self, far, k_bend, SpringFamily::kBend);
      }
    }
  }
  lat.touch();
  return lat;
}

}  // namespace palpate
