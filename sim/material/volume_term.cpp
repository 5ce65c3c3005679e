#include "sim/material/volume_term.h"

#include <cmath>

namespace palpate {

double volume_pressure_Pa(double volume_Pa, double j) {
  const double s = j - 1.0;
  if (volume_Pa >= 0.0 || std::abs(s) <= kVolumeSoftening) return volume_Pa * s;
  return volume_Pa * std::copysign(kVolumeSoftening, s);
}

namespace {

// one cell's energy per l^3
double volume_energy_density(double volume_Pa, double j) {
  const double s = j - 1.0;
  if (volume_Pa >= 0.0 || std::abs(s) <= kVolumeSoftening) return 0.5 * volume_Pa * s * s;
  return 0.5 * volume_Pa * kVolumeSoftening * (2.0 * std::abs(s) - kVolumeSoftening);
}

}  // namespace

Vec3 corner_gradient(int corner, double cell_m) {
  const double q = 0.25 / cell_m;
  return Vec3((corner & 1) ? q : -q, (corner & 2) ? q : -q, (corner & 4) ? q : -q);
}

Mat3 cell_deformation_gradient(const std::vector<Vec3>& x_m, const std::array<int32_t, 8>& nodes, double cell_m) {
  // F = sum_a x_a g_a^T; the sums of signs per axis are differences of the four corners on either side
  Vec3 col[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  for (int a = 0; a < 8; ++a) {
    const Vec3& x = x_m[static_cast<std::size_t>(nodes[a])];
    for (int axis = 0; axis < 3; ++axis) col[axis] += (a & (1 << axis)) ? x : Vec3(-x);
  }
  Mat3 f;
  const double q = 0.25 / cell_m;
  for (int axis = 0; axis < 3; ++axis) f.col(axis) = q * col[axis];
  return f;
}

Mat3 cofactor(const Mat3& f) {
  Mat3 c;
  c.col(0) = f.col(1).cross(f.col(2));
  c.col(1) = f.col(2).cross(f.col(0));
  c.col(2) = f.col(0).cross(f.col(1));
  return c;
}

void add_volume_forces(const Lattice& lat, const std::vector<Vec3>& x_m, std::vector<Vec3>* f_N) {
  if (lat.volume_Pa == 0.0) return;
  for (std::size_t k = 0; k < lat.cell_nodes.size(); ++k) {
    const auto& nodes = lat.cell_nodes[k];
    const double l = lat.cell_edge_m(k);
    const Mat3 f = cell_deformation_gradient(x_m, nodes, l);
    const Mat3 cof = cofactor(f);
    const double j = f.col(0).dot(cof.col(0));
    // -dE/dx_a = -l^3 psi'(J) cof(F) g_a
    const double volume_m3 = l * l * l;
    const Mat3 p = (-volume_m3 * volume_pressure_Pa(lat.volume_Pa, j)) * cof;
    for (int a = 0; a < 8; ++a) (*f_N)[static_cast<std::size_t>(nodes[a])] += p * corner_gradient(a, l);
  }
}

double volume_energy_J(const Lattice& lat, const std::vector<Vec3>& x_m) {
  if (lat.volume_Pa == 0.0) return 0.0;
  double e = 0.0;
  for (std::size_t k = 0; k < lat.cell_nodes.size(); ++k) {
    const double l = lat.cell_edge_m(k);
    e += l * l * l * volume_energy_density(lat.volume_Pa, cell_deformation_gradient(x_m, lat.cell_nodes[k], l).determinant());
  }
  return e;
}

void volume_gradients(const Lattice& lat, const std::vector<Vec3>& x_m, std::vector<std::array<Vec3, 8>>* c,
                      std::vector<double>* w_J) {
  c->resize(lat.cell_nodes.size());
  w_J->resize(lat.cell_nodes.size());
  for (std::size_t k = 0; k < lat.cell_nodes.size(); ++k) {
    const double l = lat.cell_edge_m(k);
    const Mat3 f = cell_deformation_gradient(x_m, lat.cell_nodes[k], l);
    const Mat3 cof = cofactor(f);
    const double s = f.col(0).dot(cof.col(0)) - 1.0;
    (*w_J)[k] = lat.volume_Pa >= 0.0 || std::abs(s) <= kVolumeSoftening ? lat.volume_Pa * (l * l * l) : 0.0;
    for (int a = 0; a < 8; ++a) (*c)[k][static_cast<std::size_t>(a)] = cof * corner_gradient(a, l);
  }
}

}  // namespace palpate
