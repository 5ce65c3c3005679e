#pragma once
/// Lattice: the local mass-spring system of paper section 4.2, built over grid cells around the contact.

#include <array>
#include <cstdint>
#include <vector>

#include "core/grid_hierarchy.h"
#include "core/result.h"
#include "core/scene.h"
#include "core/types.h"

namespace palpate {

/// Spring families of section 4.2 (the paper's "flexible" springs are the bend family here).
enum class SpringFamily : uint8_t { kStructural = 0, kShear = 1, kBend = 2 };

/// One Hooke spring between two nodes (eq. 2), with relative-velocity damping (eq. 4).
struct Spring {
  int32_t a = 0, b = 0;          ///< node indices
  double rest_m = 0.0;           ///< l0
  double k_N_per_m = 0.0;        ///< stiffness K of its family
  SpringFamily family = SpringFamily::kStructural;
};

/// A node of a refined lattice lying on a coarse cell's face or edge (a hanging node): its position and velocity are
/// those of the coarse cell's surface there, x = sum_k weight_k x_master_k (bilinear on a face, linear on an edge).
struct HangingNode {
  int32_t node = 0;                 ///< the constrained node
  int count = 0;                    ///< masters used (2 on an edge, 4 on a face)
  std::array<int32_t, 4> master{};  ///< the coarse cell's corner nodes it lies between
  std::array<double, 4> weight{};   ///< their weights (sum 1)
};

/// Nodes, springs and state of a lattice. Plain data; copyable. Built by build_lattice().
struct Lattice {
  int level = 0;                         ///< grid level of the cells
  int cells_per_axis = 0;                ///< grid cells per axis at that level
  double cell_m = 0.0;                   ///< cell edge length
  double damping_Ns_per_m = 0.0;         ///< C_d per spring
  double volume_Pa = 0.0;                ///< lambda_v of every cell's volume term (sim/material/volume_term.h); 0 = none
  double neo_mu_Pa = 0.0;                ///< mu of every cell's Neo-Hookean term (sim/material/neo_hookean_term.h); 0 = none
  double neo_lambda_Pa = 0.0;            ///< lambda of that term
  Vec3 gravity_m_per_s2 = Vec3::Zero();  ///< g (eq. 6)
  std::vector<int32_t> cells;            ///< grid cell index of each region cell (n_c)
  std::vector<std::array<int32_t, 8>> cell_nodes;  ///< node of each cell corner, corner = dx + 2dy + 4dz (n_c)
  std::vector<int32_t> slot_of_cell;     ///< region slot of each grid cell at `level`, -1 outside (n_grid_cells)
  std::vector<Vec3> rest_m;              ///< rest positions (n)
  std::vector<Vec3> x_m;                 ///< positions (n)
  std::vector<Vec3> v_m_per_s;           ///< velocities (n)
  std::vector<double> mass_kg;           ///< node masses (n)
  std::vector<uint8_t> fixed;            ///< 1 = held at rest (region border / floor) (n)
  std::vector<uint8_t> held_dof;         ///< DOFs (3n; empty: none) held where they are one axis at a time, a sliding
                                         ///< support (forces there zeroed; local_global reports it as a failed solve)
  std::vector<Spring> springs;           ///< all springs (n_s)
  std::array<int, 3> springs_per_family{};  ///< counts by SpringFamily
  std::vector<int32_t> grid_node;        ///< grid vertex index i + (N+1)(j + (N+1)k) of each node (n)
  std::vector<int32_t> cell_span;        ///< edge of each cell in units of cell_m (n_c; empty: every cell 1), > 1 for
                                         ///< the coarse cells of a refined lattice (sim/lattice/refined_lattice.h)
  std::vector<HangingNode> hanging;      ///< nodes held on coarse faces, masters first (empty: none; sim/lattice/hanging.h)
  uint64_t revision = 0;                 ///< changes whenever nodes, springs or parameters change (solver caches key on it)

  std::size_t num_nodes() const { return x_m.size(); }
  /// Edge of region cell `slot` (m): cell_m, times its span in a refined lattice.
  double cell_edge_m(std::size_t slot) const { return cell_span.empty() ? cell_m : cell_m * cell_span[slot]; }
  /// Local coordinates in [0,1]^3 of the rest point p_m in region cell `slot` (clamped to the cell).
  Vec3 local_in_cell(std::size_t slot, const Vec3& p_m) const {
    return ((p_m - rest_m[static_cast<std::size_t>(cell_nodes[slot][0])]) / cell_edge_m(slot)).cwiseMax(0.0).cwiseMin(1.0);
  }
  /// Puts every node back at rest with zero velocity.
  void reset_to_rest();
  /// Marks nodes, springs or parameters as changed, so factorisations cached by integrators are rebuilt.
  void touch();
};

/// Cells of the region: solid cells at `level` within Chebyshev distance `radius_cells` of `center`.
std::vector<int32_t> region_cells(const GridHierarchy& grid, int level, const CellCoord& center, int radius_cells);

/// Builds a lattice over `cells` (grid indices at spec.level): nodes at their corners, the families whose
/// stiffness is non-zero, border nodes (shared with solid cells outside the region) fixed, and with
/// spec.fix_floor the nodes on the model's lowest node plane fixed too. With spec.material enabled, k, M and C_d
/// come from the material (sim/material/material.h) and each cell adds its share to the springs it shares with others;
/// otherwise a shared spring keeps the one raw k. Errors when `cells` is empty.
Result<Lattice> build_lattice(const GridHierarchy& grid, const LatticeSpec& spec, const std::vector<int32_t>& cells);

}  // namespace palpate
