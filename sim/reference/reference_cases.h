#pragma once
/// Continuum references for the material calibration (sim/material/material.h): small lattices with closed-form answers,
/// brought to rest by their own integrator (sim/reference/settle.h). Shared by the tests and `palpate bench model` (whose
/// third reference, Hertz indentation by the sphere tool, runs the servo and frame stage: runtime/session/tool_hold.h).

#include <array>
#include <cstdint>
#include <vector>

#include "core/grid_hierarchy.h"
#include "core/result.h"
#include "core/scene.h"
#include "sim/lattice/lattice.h"
#include "sim/reference/settle.h"

namespace palpate {

/// A material lattice with its boundary conditions and load. Plain data; copyable.
struct ReferenceCase {
  Lattice lattice;                 ///< built with the material; x_m holds the prescribed displacements
  std::vector<uint8_t> held_dof;   ///< DOFs held at x_m (3n; the fixed nodes' DOFs; empty: none), for solve_static
  std::vector<Vec3> f_ext_N;       ///< applied load (n)
  double closed_form = 0.0;        ///< the continuum answer (N for compression, m for the cantilever)
};

/// What a reference gives: the lattice's answer against the closed form.
struct ReferenceCheck {
  double model = 0.0;              ///< lattice answer, same unit as closed_form (displacement under the load, m)
  double closed_form = 0.0;        ///< continuum answer
  double rel_error = 0.0;          ///< force error: the force the lattice needs for the closed form's displacement
                                   ///< over the closed form's force, minus 1 (closed_form / model - 1; > 0: too stiff)
  double poisson_effective = 0.0;  ///< compression: lateral over axial strain; cantilever: 0
  std::size_t nodes = 0;           ///< lattice nodes
  std::size_t springs = 0;         ///< lattice springs
  SettleReport settle;             ///< frames to rest, substeps, ms per frame
};

/// A grid of `levels` levels over the cube [0, cube_m]^3 of a box of size_m in its corner, the box's faces a hair inside
/// the cell planes (so its cells are exactly those the box fills when size_m is a whole number of cells). Errors as
/// GridHierarchy::build.
Result<GridHierarchy> box_grid(const Vec3& size_m, double cube_m, int levels);

/// A lattice at `level` over a box of cells[0] x cells[1] x cells[2] cells in the corner of a grid cube of side
/// cube_m (cells at that level: cube_m / 2^(level-1)); no node fixed. Errors name the level and cell counts.
Result<Lattice> box_lattice(const MaterialSpec& material, double cube_m, int level, const std::array<int, 3>& cells);

/// Uniaxial compression of a cube of side 4 cm (the whole grid at `level`): the top face pushed down and the bottom
/// face up by a uniform pressure E x strain (nodal forces by area shares), nothing held (the loads balance, so the
/// cube does not move as a whole). Closed form: it shortens by strain x side, exact for nu = 1/4 (m).
Result<ReferenceCase> compression_case(const MaterialSpec& material, int level, double strain);

/// A cantilever of length 8 cm and square section 1 cm (slenderness 8; needs level >= 4) clamped at x = 0 (those
/// nodes fixed), loaded in -z at the free end by a force spread over the end face's nodes by their area shares,
/// sized for a deflection of 1e-4 of the length. Closed form F L^3 / (3 E I), I = h^4 / 12 (m), Euler-Bernoulli:
/// shear deformation adds about 1.2 % for this slenderness at nu = 1/4 (Timoshenko).
Result<ReferenceCase> cantilever_case(const MaterialSpec& material, int level);

/// Brings a compression case to rest with `settle` and compares its shortening with the closed form.
Result<ReferenceCheck> check_compression(const MaterialSpec& material, int level, double strain,
                                         const SettleOptions& settle = {});

/// Brings a cantilever case to rest and compares the end face's mean deflection (load-weighted) with the closed form.
Result<ReferenceCheck> check_cantilever(const MaterialSpec& material, int level, const SettleOptions& settle = {});

/// Nominal (first Piola) axial stress of the compressible Neo-Hookean solid psi = mu/2 (tr F^T F - 3) - mu ln J +
/// lambda/2 (ln J)^2 under uniaxial stress at axial stretch a (Pa; < 0 in compression); *lateral gets the lateral
/// stretch b, the root of mu (b^2 - 1) + lambda ln(a b^2) = 0.
double neo_hookean_uniaxial_Pa(double mu_Pa, double lambda_Pa, double a, double* lateral);

/// Uniaxial compression of the 4 cm cube at large strain between frictionless plates: the top and bottom faces held
/// in z and free to spread (settle's held DOFs), moved together by `strain` (e.g. 0.3, level >= 2) in three
/// increments, each run to rest. model: the plates' force (N); closed_form: the compressible Neo-Hookean solid's
/// uniaxial nominal stress for that stretch times the face (N, neo_hookean_uniaxial_Pa); rel_error: model over
/// closed_form minus 1 (> 0: too stiff); poisson_effective: the lateral stretch reached over the closed form's, minus 1.
Result<ReferenceCheck> check_large_compression(const MaterialSpec& material, int level, double strain,
                                               const SettleOptions& settle = {});

/// The end face's load-weighted mean deflection of a cantilever case whose lattice is `lat` (m, > 0 downwards).
double cantilever_deflection_m(const ReferenceCase& c, const Lattice& lat);

}  // namespace palpate
