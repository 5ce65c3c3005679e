#include "sim/lattice/hanging.h"

namespace palpate {

void spread_hanging(const Lattice& lat, std::vector<Vec3>* v) {
  // in list order: a node whose masters hang comes after them (sim/lattice/refined_lattice.h), so one pass is exact
  for (const HangingNode& h : lat.hanging) {
    Vec3 s = Vec3::Zero();
    for (int k = 0; k < h.count; ++k) s += h.weight[static_cast<std::size_t>(k)] * (*v)[static_cast<std::size_t>(h.master[static_cast<std::size_t>(k)])];
    (*v)[static_cast<std::size_t>(h.node)] = s;
  }
}

void fold_hanging(const Lattice& lat, std::vector<Vec3>* f) {
  // in reverse: a hanging master's share is folded on before the master's own entry moves on
  for (auto it = lat.hanging.rbegin(); it != lat.hanging.rend(); ++it) {
    const HangingNode& h = *it;
    const Vec3 fh = (*f)[static_cast<std::size_t>(h.node)];
    for (int k = 0; k < h.count; ++k)
      (*f)[static_cast<std::size_t>(h.master[static_cast<std::size_t>(k)])] += h.weight[static_cast<std::size_t>(k)] * fh;
    (*f)[static_cast<std::size_t>(h.node)].setZero();
  }
}

void mark_hanging(const Lattice& lat, std::vector<uint8_t>* mask) {
  for (const HangingNode& h : lat.hanging) (*mask)[static_cast<std::size_t>(h.node)] = 1;
}

}  // namespace palpate
