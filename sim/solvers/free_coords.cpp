#include "sim/solvers/free_coords.h"

#include <utility>

#include "sim/lattice/hanging.h"

namespace palpate {

FreeCoords free_coords(const Lattice& lat, const std::vector<uint8_t>& held_dof, int extra) {
  const std::size_t n = lat.num_nodes();
  std::vector<uint8_t> hangs(n, 0);
  mark_hanging(lat, &hangs);
  FreeCoords fc;
  fc.extra = extra;
  fc.col.assign(3 * n, -1);
  int free = 0;
  for (std::size_t d = 0; d < 3 * n; ++d) {
    const bool held = held_dof.empty() ? lat.fixed[d / 3] != 0 : held_dof[d] != 0;
    if (hangs[d / 3]) {
      fc.col[d] = fc.lattice_rows++;
      fc.q_of.push_back(-1);
    } else if (!held) {
      fc.col[d] = fc.lattice_rows++;
      fc.q_of.push_back(free++);
    }
  }
  fc.free = free + extra;
  if (lat.hanging.empty()) return fc;
  // each hanging DOF as a combination of free coordinates, in list order (a hanging master's comes first)
  using Terms = std::vector<std::pair<int, double>>;
  std::vector<Terms> row(3 * n);
  for (std::size_t d = 0; d < 3 * n; ++d)
    if (fc.col[d] >= 0 && !hangs[d / 3]) row[d] = {{fc.q_of[static_cast<std::size_t>(fc.col[d])], 1.0}};
  for (const HangingNode& h : lat.hanging)
    for (int a = 0; a < 3; ++a) {
      Terms& t = row[3 * static_cast<std::size_t>(h.node) + static_cast<std::size_t>(a)];
      t.clear();
      for (int k = 0; k < h.count; ++k) {
        const auto m = static_cast<std::size_t>(h.master[static_cast<std::size_t>(k)]);
        for (const auto& [q, w] : row[3 * m + static_cast<std::size_t>(a)])
          t.emplace_back(q, h.weight[static_cast<std::size_t>(k)] * w);
      }
    }
  std::vector<Eigen::Triplet<double>> trip;
  for (std::size_t d = 0; d < 3 * n; ++d)
    if (fc.col[d] >= 0)
      for (const auto& [q, w] : row[d]) trip.emplace_back(fc.col[d], q, w);
  for (int e = 0; e < extra; ++e) trip.emplace_back(fc.lattice_rows + e, free + e, 1.0);
  fc.p.resize(fc.assembled(), fc.free);
  fc.p.setFromTriplets(trip.begin(), trip.end());
  return fc;
}

Eigen::SparseMatrix<double> reduce_stiffness(const FreeCoords& fc, Eigen::SparseMatrix<double> k) {
  if (fc.p.size() == 0) return k;
  return fc.p.transpose() * k * fc.p;
}

void reduce_forces(const Lattice& lat, const FreeCoords& fc, std::vector<Vec3>* f, Eigen::VectorXd* r) {
  fold_hanging(lat, f);
  for (std::size_t d = 0; d < fc.col.size(); ++d) {
    const int c = fc.col[d];
    if (c >= 0 && fc.q_of[static_cast<std::size_t>(c)] >= 0) (*r)[fc.q_of[static_cast<std::size_t>(c)]] = (*f)[d / 3][static_cast<int>(d % 3)];
  }
}

void move_free(const FreeCoords& fc, const std::vector<Vec3>& from_m, const Eigen::VectorXd& dq, double step, Lattice* lat) {
  for (std::size_t d = 0; d < fc.col.size(); ++d) {
    const int c = fc.col[d];
    if (c >= 0 && fc.q_of[static_cast<std::size_t>(c)] >= 0)
      lat->x_m[d / 3][static_cast<int>(d % 3)] = from_m[d / 3][static_cast<int>(d % 3)] + step * dq[fc.q_of[static_cast<std::size_t>(c)]];
  }
  spread_hanging(*lat, &lat->x_m);
}

}  // namespace palpate
