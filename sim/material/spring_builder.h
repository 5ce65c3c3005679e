#pragma once
/// SpringBuilder: adds a lattice's springs once per node pair (used by build_lattice and build_refined_lattice).
/// Raw keys: a spring shared by several cells keeps one k (the paper's lattice). Material (accumulate): every cell
/// adds its share, so a shared spring carries the sum (sim/material/material.h).

#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include "core/pair_key.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// Collects springs into *lat; plain data over the lattice it fills.
struct SpringBuilder {
  Lattice* lat = nullptr;                        ///< the lattice being built (rest_m filled)
  std::unordered_set<uint64_t> seen;             ///< node pairs with a spring (or a known edge)
  bool accumulate = false;                       ///< material: a shared spring sums its cells' shares
  std::unordered_map<uint64_t, int32_t> index;   ///< spring of each pair (accumulate mode)

  /// Adds k between nodes a and b (or to the spring already there, in accumulate mode).
  void add(int32_t a, int32_t b, double k, SpringFamily fam) {
    const uint64_t key = unordered_pair_key(a, b);
    if (!seen.insert(key).second) {
      if (accumulate) lat->springs[static_cast<std::size_t>(index.at(key))].k_N_per_m += k;
      return;
    }
    if (accumulate) index.emplace(key, static_cast<int32_t>(lat->springs.size()));
    Spring s;
    s.a = a;
    s.b = b;
    s.rest_m = (lat->rest_m[static_cast<std::size_t>(b)] - lat->rest_m[static_cast<std::size_t>(a)]).norm();
    s.k_N_per_m = k;
    s.family = fam;
    lat->springs.push_back(s);
    lat->springs_per_family[static_cast<int>(fam)]++;
  }

  /// A cell's 12 edges (k_edge) and its 6 x 2 face and 4 body diagonals (k_diagonal); 0 leaves a family out.
  void add_cell(const std::array<int32_t, 8>& cn, double k_edge, double k_diagonal) {
    if (k_edge > 0.0)
      for (int corner = 0; corner < 8; ++corner)
        for (int axis = 0; axis < 3; ++axis)
          if (!(corner & (1 << axis))) add(cn[corner], cn[corner | (1 << axis)], k_edge, SpringFamily::kStructural);
    if (!(k_diagonal > 0.0)) return;
    for (int normal = 0; normal < 3; ++normal) {
      const int u = 1 << ((normal + 1) % 3), w = 1 << ((normal + 2) % 3);
      for (int side = 0; side < 2; ++side) {
        const int base = side ? (1 << normal) : 0;
        add(cn[base], cn[base | u | w], k_diagonal, SpringFamily::kShear);
        add(cn[base | u], cn[base | w], k_diagonal, SpringFamily::kShear);
      }
    }
    for (int corner = 0; corner < 4; ++corner) add(cn[corner], cn[7 - corner], k_diagonal, SpringFamily::kShear);
  }
};

}  // namespace palpate
