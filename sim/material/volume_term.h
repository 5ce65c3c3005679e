#pragma once
/// The per-cell volume term of material.model "volumetric" (sim/material/material.h): each region cell stores
/// (1/2) lambda_v l^3 (J - 1)^2, l the cell's own edge (Lattice::cell_edge_m: a refined lattice's cells differ),
/// J = det F of the cell's deformation gradient at its centre, F = sum_a x_a g_a^T with g_a = s_a / (4 l) the
/// trilinear shape functions' gradients there (s_a the corner's signs, +-1 per axis). The force on corner a is
/// -lambda_v l^3 (J - 1) cof(F) g_a (dJ/dF = cof F). Exact under rotation; one quadrature point per cell, so only a
/// cell's mean volume change is penalised and nothing locks as nu -> 1/2. A negative lambda_v (nu < 1/4) is quadratic
/// only while |J - 1| <= kVolumeSoftening and linear beyond (its force stays at the value there): a softening term
/// unbounded below would let a cell blow up under large stretch. Thread: the stepping thread; no allocation once the
/// buffers have their size.

#include <array>
#include <cstdint>
#include <vector>

#include "sim/lattice/lattice.h"

namespace palpate {

/// |J - 1| beyond which a negative volume term stops growing (its energy continues linearly).
inline constexpr double kVolumeSoftening = 0.1;

/// d psi / dJ of a cell's volume energy density psi: lambda_v (J - 1), held at +-lambda_v kVolumeSoftening beyond
/// that when lambda_v < 0 (Pa).
double volume_pressure_Pa(double volume_Pa, double j);

/// Gradient g_a of corner a's trilinear shape function at the centre of a cube of edge cell_m (1/m).
Vec3 corner_gradient(int corner, double cell_m);

/// Deformation gradient at the centre of the cell whose corner nodes are `nodes`, positions x_m.
Mat3 cell_deformation_gradient(const std::vector<Vec3>& x_m, const std::array<int32_t, 8>& nodes, double cell_m);

/// Cofactor matrix of f (d det f / d f): its columns are the cross products of f's other two columns.
Mat3 cofactor(const Mat3& f);

/// Adds every cell's volume force at positions x_m to *f_N (n; fixed nodes included). Nothing when lat.volume_Pa is 0.
void add_volume_forces(const Lattice& lat, const std::vector<Vec3>& x_m, std::vector<Vec3>* f_N);

/// The volume term's energy at positions x_m, J.
double volume_energy_J(const Lattice& lat, const std::vector<Vec3>& x_m);

/// Per-cell vectors c_a = cof(F) g_a (cells x 8, 1/m) and weights w = l^3 d^2 psi / dJ^2 (cells, J) of the volume term's Gauss-Newton stiffness w c_a c_b^T (the implicit integrators' and the static solve's
/// tangent), at positions x_m.
void volume_gradients(const Lattice& lat, const std::vector<Vec3>& x_m, std::vector<std::array<Vec3, 8>>* c,
                      std::vector<double>* w_J);

}  // namespace palpate
