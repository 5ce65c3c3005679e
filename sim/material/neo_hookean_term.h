#pragma once
/// The per-cell Neo-Hookean term of material.model "neo_hookean" (sim/material/material.h): each region cell stores
/// l^3 psi(F), l the cell's own edge (Lattice::cell_edge_m), psi = mu/2 (tr F^T F - 3) - mu ln J + lambda/2 (ln J)^2
/// (compressible Neo-Hookean; Bonet & Wood), F the cell's deformation gradient at its centre (sim/material/volume_term.h).
/// First Piola stress P = mu (F - F^-T) + lambda ln J F^-T; corner a gets -l^3 P g_a. One quadrature point per cell:
/// nothing locks as nu -> 1/2, and the lattice's springs (a share of the stiffness) hold the cell's hourglass modes.
/// A cell turned inside out (J <= kMinCellJ) is pushed back by the stress at kMinCellJ: its energy continues linearly
/// in J below there, so forces stay its gradient. Thread: the stepping thread.

#include <array>
#include <vector>

#include "sim/lattice/lattice.h"

namespace palpate {

/// A 9x9 matrix on vec(F), column-major (entry i + 3 j is F_ij).
using Mat9 = Eigen::Matrix<double, 9, 9>;

/// Smallest J the Neo-Hookean stress is evaluated at (a cell squashed further keeps that stress).
inline constexpr double kMinCellJ = 1e-2;

/// One cell's state for the tangent: F^-T and ln J at the configuration it was taken at, and the cell's edge. Plain data.
struct NeoHookeanCell {
  Mat3 f_inv_t = Mat3::Identity();  ///< F^-T
  double log_j = 0.0;               ///< ln J
  double edge_m = 0.0;              ///< the cell's edge l (Lattice::cell_edge_m: a refined lattice's cells differ)
};

/// First Piola stress of the term at F (Pa).
Mat3 neo_hookean_stress_Pa(double mu_Pa, double lambda_Pa, const Mat3& f);

/// Adds every cell's Neo-Hookean force at positions x_m to *f_N (n). Nothing when lat.neo_mu_Pa is 0.
void add_neo_hookean_forces(const Lattice& lat, const std::vector<Vec3>& x_m, std::vector<Vec3>* f_N);

/// The term's energy at positions x_m, J.
double neo_hookean_energy_J(const Lattice& lat, const std::vector<Vec3>& x_m);

/// Every cell's tangent state at positions x_m, with its edge (cells).
void neo_hookean_cells(const Lattice& lat, const std::vector<Vec3>& x_m, std::vector<NeoHookeanCell>* cells);

/// y += K p over the cells: K the term's tangent stiffness (l^3 dP(dF) g_b with dF = sum_a p_a g_a^T).
void add_neo_hookean_product(const Lattice& lat, const std::vector<NeoHookeanCell>& cells, const std::vector<Vec3>& p,
                             std::vector<Vec3>* y);

/// The tangent's 3x3 block K_ba (row node b, column node a) of one cell: l^3 [mu (g_a.g_b) I + (mu - lambda ln J)
/// h_a h_b^T + lambda h_b h_a^T], h = F^-T g.
Mat3 neo_hookean_block(const Lattice& lat, const NeoHookeanCell& cell, int b, int a);

/// The term's energy density's Hessian d^2 psi / dF^2 at f, on vec(f) (Pa), with its negative eigenvalues raised to
/// zero: positive semi-definite at any F, inverted cells included (P = mu F + a(J) cof F, a = (lambda ln J - mu) / J,
/// held at kMinCellJ below it). For the projected Newton step of implicit Euler (sim/solvers/implicit_euler.h).
Mat9 neo_hookean_projected_hessian(double mu_Pa, double lambda_Pa, const Mat3& f);

}  // namespace palpate
