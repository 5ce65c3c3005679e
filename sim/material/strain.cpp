#include "sim/material/strain.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace palpate {

double cell_equivalent_strain(const std::array<Vec3, 8>& rest_m, const std::array<Vec3, 8>& x_m) {
  // the shape functions' gradients at the centre of the reference cube [0, 1]^3: +-1/4 along each axis
  Eigen::Matrix3d dx = Eigen::Matrix3d::Zero(), dX = Eigen::Matrix3d::Zero();
  for (int c = 0; c < 8; ++c) {
    const Vec3 g(0.25 * ((c & 1) ? 1.0 : -1.0), 0.25 * ((c & 2) ? 1.0 : -1.0), 0.25 * ((c & 4) ? 1.0 : -1.0));
    dx += x_m[c] * g.transpose();
    dX += rest_m[c] * g.transpose();
  }
  const double det = dX.determinant();
  if (!(std::abs(det) > 1e-30) || !std::isfinite(det)) return 0.0;
  const Eigen::Matrix3d F = dx * dX.inverse();
  const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d dev = E - (E.trace() / 3.0) * Eigen::Matrix3d::Identity();
  const double eq = std::sqrt(2.0 / 3.0 * dev.squaredNorm());
  return std::isfinite(eq) ? eq : 0.0;
}

void node_equivalent_strain(const Lattice& lat, std::vector<double>* out, std::vector<int>* count) {
  out->assign(lat.num_nodes(), 0.0);
  count->assign(lat.num_nodes(), 0);
  std::array<Vec3, 8> rest, x;
  for (const auto& nodes : lat.cell_nodes) {
    for (int c = 0; c < 8; ++c) {
      rest[c] = lat.rest_m[static_cast<std::size_t>(nodes[c])];
      x[c] = lat.x_m[static_cast<std::size_t>(nodes[c])];
    }
    const double e = cell_equivalent_strain(rest, x);
    for (int c = 0; c < 8; ++c) {
      (*out)[static_cast<std::size_t>(nodes[c])] += e;
      ++(*count)[static_cast<std::size_t>(nodes[c])];
    }
  }
  for (std::size_t i = 0; i < out->size(); ++i)
    if ((*count)[i] > 0) (*out)[i] /= (*count)[i];
}

}  // namespace palpate
