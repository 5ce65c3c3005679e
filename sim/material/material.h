#pragma once
/// Material in physical units: spring constants, node masses and damping of a cubic lattice from Young's modulus,
/// Poisson's ratio and density, by homogenisation of the lattice's central springs.
///
/// Calibration (Born's homogenisation of central-force lattices; Kot, Nagahashi & Szymczak, "Elastic moduli of
/// simple mass spring models", The Visual Computer 31, 2015; Kot & Nagahashi, "Second degree of freedom of
/// elastic objects: adjustable Poisson's ratio for mass spring models", GRAPP 2015). Under a uniform strain a
/// spring of stiffness k, rest length L and direction n stores (1/2) k L^2 (n.eps.n)^2, so a cell of volume l^3
/// has the stiffness tensor C_ijkl = (1/l^3) sum_springs k L^2 n_i n_j n_k n_l. Each CELL contributes k_e to each
/// of its 12 edges (an interior edge, shared by 4 cells, so carries 4 k_e), k_f to each of its 12 face diagonals
/// (shared by 2) and k_b to each of its 4 body diagonals. Summing (edges: L^2 = l^2, n_x^4 = 1 on 4 of them;
/// face diagonals: L^2 = 2 l^2, n_x^4 = n_x^2 n_y^2 = 1/4 on 8 resp. 4; body diagonals: L^2 = 3 l^2, 1/9 on 4):
///   C11 = (4 k_e + 4 k_f + 4/3 k_b) / l,    C12 = C44 = (2 k_f + 4/3 k_b) / l.
/// Central forces impose the Cauchy relation C12 = C44, i.e. lambda = mu, so the only isotropic Poisson ratio a
/// cubic lattice of central springs can represent is nu = lambda / (2 (lambda + mu)) = 1/4. With one shear family
/// (k_f = k_b = k_s), isotropy C11 = C12 + 2 C44 = 3 C44 gives k_e = 7/6 k_s; E = mu (3 lambda + 2 mu) /
/// (lambda + mu) = 5/2 mu with mu = 10/3 k_s / l gives
///   k_s = 3 E l / 25,    k_e = 7 E l / 50,    bend springs 0 (they would add to C11 only).
/// Outside nu = 1/4 the calibration keeps E exact and the lattice's nu stays 1/4 (calibrate_lattice() says so in
/// its warning). Under a uniform strain every cell's springs put on each corner the force sigma . (l^2/4) n of a
/// uniformly stressed hexahedron, so a homogeneous block under uniaxial stress deforms uniformly and
/// F = E A d / L holds to round-off at small strain.
///
/// Volumetric model (material.model "volumetric", any nu in [0, 0.49]): the springs are calibrated as above for
/// the asked shear modulus mu = E / (2 (1 + nu)) (the spring lattice's own Young's modulus 5/2 mu), which gives
/// lambda_s = mu; each cell adds the volume energy (1/2) lambda_v l^3 (J - 1)^2 with J = det F of the cell's
/// centre deformation gradient (sim/material/volume_term.h) and lambda_v = lambda - mu, lambda = E nu / ((1 + nu)(1 - 2 nu)):
/// at small strain J - 1 = tr eps, so the cell's stiffness is C = 2 mu I + lambda I (x) I, the isotropic solid of
/// (E, nu). One quadrature point per cell for the volume (reduced integration of the volumetric term) leaves
/// nothing to lock as nu -> 1/2: the springs hold the cell's hourglass modes. lambda_v < 0 for nu < 1/4 (down to
/// -mu at nu = 0): the cell's bulk modulus lambda + 2/3 mu stays positive.
///
/// Neo-Hookean model (material.model "neo_hookean", nu in [0, 0.49], large strain): the springs carry a share
/// kNeoHookeanSpringShare of the shear modulus (the nu = 1/4 calibration for Young's modulus 5/2 s mu, so their
/// lambda is s mu too) and each cell the compressible Neo-Hookean solid psi = mu_n/2 (tr F^T F - 3) - mu_n ln J +
/// lambda_n/2 (ln J)^2 of the rest, mu_n = (1 - s) mu, lambda_n = lambda - s mu, at its centre
/// (sim/material/neo_hookean_term.h): at small strain the sum is the isotropic solid of (E, nu); at large strain all but the
/// springs' share follows Neo-Hooke (the springs, Hookean in length, are softer in compression and stiffer in
/// tension). The springs hold the cells' hourglass modes, which the one-point term does not see.
///
/// Damping: every spring gets one relative-velocity coefficient c (the integrators take one per lattice), and the
/// force c (v_b - v_a) of the paper's eq. 4 acts on the whole relative velocity, not only along the spring. Under a
/// uniform velocity gradient G it dissipates (1/l^3) sum c L^2 |G n|^2 per volume; with per-cell shares c/4, c/2, c
/// that is eta |G|^2 with eta = 9 c / l: a viscous stress eta G. Matching a Kelvin-Voigt solid with viscosity
/// beta * C (Rayleigh stiffness-proportional damping beta; a mode of angular frequency w then has damping ratio
/// beta w / 2) in simple shear, eta = beta mu, gives c = beta mu l / 9 = 2/45 beta E l. Its dilatational viscosity
/// is then 1/3 of beta (lambda + 2 mu), and unlike Kelvin-Voigt it also damps spin: rigid rotation and the
/// rotation of cross-sections in bending, so the bending modes of slender parts are damped more than beta w / 2.
/// Masses: each region cell gives 1/8 of its solid volume to each corner. The solid volume of a cell is l^3 times
/// the mean solid fraction of its leaf cells (GridHierarchy::leaf_solid_fraction: cells crossed by the surface
/// count the inside length of 16 lines through them by the parity of their crossings with the mesh; where the mesh
/// is not closed along a line the cell counts whole).

#include <string>
#include <vector>

#include "core/grid_hierarchy.h"
#include "core/scene.h"

namespace palpate {

/// The Poisson ratio a cubic lattice of central springs represents (the Cauchy relation lambda = mu).
inline constexpr double kLatticePoissonRatio = 0.25;

/// Share of the shear modulus the springs carry in the Neo-Hookean model (the rest is the cells' Neo-Hookean term).
inline constexpr double kNeoHookeanSpringShare = 0.1;

/// Share of the shear modulus the springs carry in the volumetric model below nu = 1/4, which takes the Neo-Hookean
/// split there (small strain): with a tenth the one-point cells left the lattice too soft under a contact (Hertz at
/// level 6, nu 0: -10.1 %), with a fifth -7.7 % (cantilever -3.3 %); the cells' bulk modulus lambda + 2/3 mu - 5/3 s mu
/// stays positive at nu 0 for s < 0.4.
inline constexpr double kVolumetricSplitSpringShare = 0.2;

/// Least mass a material lattice's node carries, as a share of a full cell's mass (a full corner carries 1/8): a
/// node whose cells the solid-fraction sampling finds empty would otherwise be massless.
inline constexpr double kMinNodeMassShare = 1.0 / 64.0;

/// Per-cell spring constants and the per-spring damping derived from a material at one cell size. Plain data.
struct LatticeCalibration {
  double edge_N_per_m = 0.0;      ///< k_e each cell adds to each of its 12 edges: 7 E l / 50
  double diagonal_N_per_m = 0.0;  ///< k_s each cell adds to each face and body diagonal: 3 E l / 25
  double damping_Ns_per_m = 0.0;  ///< c of every spring: 2/45 beta E l (E = 5/2 mu for the split models)
  double volume_Pa = 0.0;         ///< lambda_v of each cell's volume term (0: springs only)
  double neo_mu_Pa = 0.0;         ///< mu of each cell's Neo-Hookean term (0: none)
  double neo_lambda_Pa = 0.0;     ///< lambda of that term
  double poisson_represented = kLatticePoissonRatio;  ///< nu of the lattice (1/4 with springs only)
  std::string warning;            ///< non-empty when the asked nu differs from the represented one
};

/// The calibration for `material` at cell edge cell_m (> 0).
LatticeCalibration calibrate_lattice(const MaterialSpec& material, double cell_m);

/// Strain a column of `height_m` of `material` takes at its foot under its own weight in gravity |g| g_m_per_s2:
/// rho g H / E (the stress rho g H over E; the column's mean strain is half of it).
double self_weight_strain(const MaterialSpec& material, double height_m, double g_m_per_s2);

/// The start-up warning when that strain is more than the material model is calibrated for ("" otherwise): 10 % for
/// the small-strain models (springs, volumetric), 30 % for neo_hookean (its checked range); beyond 100 % the column
/// cannot carry itself and the lattice folds. `height_said` names the height (e.g. "the 0.06 m tall box").
std::string self_weight_warning(const MaterialSpec& material, double height_m, double g_m_per_s2,
                                const std::string& height_said);

/// Fraction in [0, 1] of the cell `index` at `level` inside the mesh: the mean solid fraction of its leaf cells.
double cell_solid_fraction(const GridHierarchy& grid, int32_t index, int level);

/// Solid volume of the whole model (leaf solid fractions x leaf cell volume; the same at every level), m^3.
double solid_volume_m3(const GridHierarchy& grid);

}  // namespace palpate
