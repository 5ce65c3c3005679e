#include "sim/material/neo_hookean_term.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "sim/material/volume_term.h"

namespace palpate {
namespace {

// F^-T and ln J of f, with J held at kMinCellJ or above (a cell turned inside out is pushed back, not made NaN);
// the cell's edge edge_m
NeoHookeanCell cell_state(const Mat3& f, double edge_m) {
  const Mat3 cof = cofactor(f);
  const double j = std::max(f.col(0).dot(cof.col(0)), kMinCellJ);
  return {cof / j, std::log(j), edge_m};
}

}  // namespace

Mat3 neo_hookean_stress_Pa(double mu_Pa, double lambda_Pa, const Mat3& f) {
  const NeoHookeanCell c = cell_state(f, 0.0);
  return mu_Pa * (f - c.f_inv_t) + lambda_Pa * c.log_j * c.f_inv_t;
}

void add_neo_hookean_forces(const Lattice& lat, const std::vector<Vec3>& x_m, std::vector<Vec3>* f_N) {
  if (lat.neo_mu_Pa == 0.0) return;
  for (std::size_t k = 0; k < lat.cell_nodes.size(); ++k) {
    const auto& nodes = lat.cell_nodes[k];
    const double l = lat.cell_edge_m(k);
    const Mat3 p = -l * l * l * neo_hookean_stress_Pa(lat.neo_mu_Pa, lat.neo_lambda_Pa, cell_deformation_gradient(x_m, nodes, l));
    for (int a = 0; a < 8; ++a) (*f_N)[static_cast<std::size_t>(nodes[a])] += p * corner_gradient(a, l);
  }
}

double neo_hookean_energy_J(const Lattice& lat, const std::vector<Vec3>& x_m) {
  if (lat.neo_mu_Pa == 0.0) return 0.0;
  double e = 0.0;
  for (std::size_t k = 0; k < lat.cell_nodes.size(); ++k) {
    const double l = lat.cell_edge_m(k);
    const Mat3 f = cell_deformation_gradient(x_m, lat.cell_nodes[k], l);
    // below kMinCellJ the force keeps the volumetric stress there: the energy continues linearly in J
    const double j = f.determinant(), log_j = std::log(std::max(j, kMinCellJ));
    const double below = j < kMinCellJ ? (lat.neo_lambda_Pa * log_j - lat.neo_mu_Pa) / kMinCellJ * (j - kMinCellJ) : 0.0;
    e += l * l * l *
         (0.5 * lat.neo_mu_Pa * (f.squaredNorm() - 3.0) - lat.neo_mu_Pa * log_j + 0.5 * lat.neo_lambda_Pa * log_j * log_j +
          below);
  }
  return e;
}

void neo_hookean_cells(const Lattice& lat, const std::vector<Vec3>& x_m, std::vector<NeoHookeanCell>* cells) {
  cells->resize(lat.cell_nodes.size());
  for (std::size_t k = 0; k < lat.cell_nodes.size(); ++k) {
    const double l = lat.cell_edge_m(k);
    (*cells)[k] = cell_state(cell_deformation_gradient(x_m, lat.cell_nodes[k], l), l);
  }
}

void add_neo_hookean_product(const Lattice& lat, const std::vector<NeoHookeanCell>& cells, const std::vector<Vec3>& p,
                             std::vector<Vec3>* y) {
  const double mu = lat.neo_mu_Pa, lambda = lat.neo_lambda_Pa;
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const auto& nodes = lat.cell_nodes[k];
    const double l = cells[k].edge_m;
    // dF = sum_a p_a g_a^T
    Mat3 df = Mat3::Zero();
    for (int a = 0; a < 8; ++a) df += p[static_cast<std::size_t>(nodes[a])] * corner_gradient(a, l).transpose();
    // dP = mu dF + (mu - lambda ln J) F^-T dF^T F^-T + lambda tr(F^-1 dF) F^-T
    const Mat3& fit = cells[k].f_inv_t;
    const Mat3 dp = mu * df + (mu - lambda * cells[k].log_j) * (fit * df.transpose() * fit) +
                    (lambda * (fit.transpose() * df).trace()) * fit;
    const Mat3 w = l * l * l * dp;
    for (int b = 0; b < 8; ++b) (*y)[static_cast<std::size_t>(nodes[b])] += w * corner_gradient(b, l);
  }
}

Mat3 neo_hookean_block(const Lattice& lat, const NeoHookeanCell& cell, int b, int a) {
  const double l = cell.edge_m;
  const Vec3 ga = corner_gradient(a, l), gb = corner_gradient(b, l);
  const Vec3 ha = cell.f_inv_t * ga, hb = cell.f_inv_t * gb;
  const double mu = lat.neo_mu_Pa, lambda = lat.neo_lambda_Pa;
  return l * l * l *
         (mu * ga.dot(gb) * Mat3::Identity() + (mu - lambda * cell.log_j) * ha * hb.transpose() +
          lambda * hb * ha.transpose());
}

Mat9 neo_hookean_projected_hessian(double mu_Pa, double lambda_Pa, const Mat3& f) {
  const Mat3 cof = cofactor(f);
  const double j = f.col(0).dot(cof.col(0));
  const double jc = std::max(j, kMinCellJ), log_j = std::log(jc);
  const double a = (lambda_Pa * log_j - mu_Pa) / jc;                                        // P = mu F + a cof F
  const double da = j > kMinCellJ ? (lambda_Pa * (1.0 - log_j) + mu_Pa) / (jc * jc) : 0.0;  // a'(J)
  Mat9 h;
  for (int c = 0; c < 9; ++c) {
    // dP for the unit dF with entry c: mu dF + a dcof(F)[dF] + a' (cof : dF) cof, dcof's columns from the cross
    // products of F's columns (cof's column k is F's other two columns crossed, cyclically)
    Mat3 e = Mat3::Zero();
    e(c % 3, c / 3) = 1.0;
    Mat3 dcof;
    for (int k = 0; k < 3; ++k) {
      const int p = (k + 1) % 3, q = (k + 2) % 3;
      dcof.col(k) = e.col(p).cross(f.col(q)) + f.col(p).cross(e.col(q));
    }
    const Mat3 dp = mu_Pa * e + a * dcof + (da * cof(c % 3, c / 3)) * cof;
    h.col(c) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dp.data());
  }
  const Eigen::SelfAdjointEigenSolver<Mat9> eig(0.5 * (h + h.transpose()));
  const Eigen::Matrix<double, 9, 1> lam = eig.eigenvalues().cwiseMax(0.0);
  return eig.eigenvectors() * lam.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace palpate
