#include "sim/cut/cut_pieces.h"

namespace palpate {

bool PieceLattice::update(const Lattice& whole, const std::vector<int32_t>& free_nodes) {
  std::vector<int32_t> part_of(whole.num_nodes(), -1);
  for (std::size_t i = 0; i < free_nodes.size(); ++i) part_of[static_cast<std::size_t>(free_nodes[i])] = static_cast<int32_t>(i);
  // the same nodes with the same springs (a cut elsewhere): nothing to rebuild
  if (free_nodes == nodes_) {
    std::size_t inside = 0;
    for (const Spring& s : whole.springs) inside += part_of[static_cast<std::size_t>(s.a)] >= 0 && part_of[static_cast<std::size_t>(s.b)] >= 0;
    if (inside == part_.springs.size()) return false;
  }
  nodes_ = free_nodes;
  const std::size_t n = nodes_.size();

  Lattice p;
  p.level = whole.level;
  p.cells_per_axis = whole.cells_per_axis;
  p.cell_m = whole.cell_m;
  p.damping_Ns_per_m = whole.damping_Ns_per_m;
  p.volume_Pa = whole.volume_Pa;
  p.neo_mu_Pa = whole.neo_mu_Pa;
  p.neo_lambda_Pa = whole.neo_lambda_Pa;
  p.gravity_m_per_s2 = whole.gravity_m_per_s2;
  p.rest_m.reserve(n);
  for (int32_t w : nodes_) {
    p.rest_m.push_back(whole.rest_m[w]);
    p.x_m.push_back(whole.x_m[w]);
    p.v_m_per_s.push_back(whole.v_m_per_s[w]);
    p.mass_kg.push_back(whole.mass_kg[w]);
    p.grid_node.push_back(whole.grid_node.empty() ? 0 : whole.grid_node[w]);
  }
  p.fixed.assign(n, 0);
  // a free piece has no spring to the rest: its springs are those with both ends in it
  for (const Spring& s : whole.springs) {
    const int32_t a = part_of[static_cast<std::size_t>(s.a)], b = part_of[static_cast<std::size_t>(s.b)];
    if (a < 0 || b < 0) continue;
    Spring c = s;
    c.a = a;
    c.b = b;
    p.springs.push_back(c);
    ++p.springs_per_family[static_cast<std::size_t>(s.family)];
  }
  // the cells whose eight corners are all in the pieces (their volume terms, when the scene has them)
  p.slot_of_cell.assign(whole.slot_of_cell.size(), -1);
  for (std::size_t c = 0; c < whole.cells.size(); ++c) {
    std::array<int32_t, 8> corners{};
    bool inside = true;
    for (int k = 0; k < 8 && inside; ++k) {
      corners[k] = part_of[static_cast<std::size_t>(whole.cell_nodes[c][k])];
      inside = corners[k] >= 0;
    }
    if (!inside) continue;
    p.slot_of_cell[static_cast<std::size_t>(whole.cells[c])] = static_cast<int32_t>(p.cells.size());
    p.cells.push_back(whole.cells[c]);
    p.cell_nodes.push_back(corners);
  }
  p.touch();
  part_ = std::move(p);
  return true;
}

void PieceLattice::push(Lattice* whole) const {
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    whole->x_m[nodes_[i]] = part_.x_m[i];
    whole->v_m_per_s[nodes_[i]] = part_.v_m_per_s[i];
  }
}

void PieceLattice::pull(const Lattice& whole) {
  for (std::size_t i = 0; i < nodes_.size(); ++i) {
    part_.x_m[i] = whole.x_m[nodes_[i]];
    part_.v_m_per_s[i] = whole.v_m_per_s[nodes_[i]];
  }
}

}  // namespace palpate
