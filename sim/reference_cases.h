#pragma once
/// Continuum references for the material calibration (sim/material.h): small lattices with closed-form answers,
/// solved for static equilibrium (sim/static_solve.h). Shared by the tests and `palpate bench material`.

#include <array>
#include <cstdint>
#include <vector>

#include "core/result.h"
#include "core/scene.h"
#include "sim/lattice.h"

namespace palpate {

/// A material lattice with its boundary conditions and load. Plain data; copyable.
struct ReferenceCase {
  Lattice lattice;                 ///< built with the material; x_m holds the prescribed displacements
  std::vector<uint8_t> held_dof;   ///< DOFs held at x_m (3n)
  std::vector<Vec3> f_ext_N;       ///< applied load (n)
  double closed_form = 0.0;        ///< the continuum answer (N for compression, m for the cantilever)
};

/// What a reference gives: the lattice's answer against the closed form.
struct ReferenceCheck {
  double model = 0.0;              ///< lattice answer, same unit as closed_form
  double closed_form = 0.0;        ///< continuum answer
  double rel_error = 0.0;          ///< (model - closed_form) / closed_form
  double poisson_effective = 0.0;  ///< compression: lateral over axial strain; cantilever: 0
  std::size_t nodes = 0;           ///< lattice nodes
  std::size_t springs = 0;         ///< lattice springs
  int newton_steps = 0;            ///< static solve iterations
};

/// A lattice at `level` over a box of cells[0] x cells[1] x cells[2] cells in the corner of a grid cube of side
/// cube_m (cells at that level: cube_m / 2^(level-1)); no node fixed. Errors name the level and cell counts.
Result<Lattice> box_lattice(const MaterialSpec& material, double cube_m, int level, const std::array<int, 3>& cells);

/// Uniaxial compression of a cube of side 4 cm (the whole grid at `level`) between frictionless plates: bottom
/// nodes held in z, top nodes moved down by strain x side and held in z, lateral faces free, rigid motion removed
/// by two bottom nodes. Closed form F = E A d / L (N), exact for nu = 1/4.
Result<ReferenceCase> compression_case(const MaterialSpec& material, int level, double strain);

/// A cantilever of length 8 cm and square section 1 cm (slenderness 8; needs level >= 4) clamped at x = 0 (every
/// DOF held), loaded in -z at the free end by a force spread over the end face's nodes by their area shares,
/// sized for a deflection of 1e-4 of the length. Closed form F L^3 / (3 E I), I = h^4 / 12 (m), Euler-Bernoulli:
/// shear deformation adds about 1.2 % for this slenderness at nu = 1/4 (Timoshenko).
Result<ReferenceCase> cantilever_case(const MaterialSpec& material, int level);

/// Hertz indentation of a block by a rigid sphere of radius 10 cm pressed 0.25 mm deep (contact radius
/// a = sqrt(R d) = 5 mm), modelled as the quarter x, y >= 0 of a block 8 cm wide and 4 cm deep (the grid cube of
/// side 4 cm at `level`, a = 1, 2, 4 cells at levels 4, 5, 6): symmetry planes hold their normal DOF, the base is
/// held in z (frictionless). Frictionless contact by active set: top nodes under the paraboloid
/// z = top - d + r^2 / (2R) are held on it, released when the sphere would have to pull. Closed form
/// F = 4/3 E* sqrt(R) d^(3/2), E* = E / (1 - nu^2) with the lattice's nu = 1/4 (N, the whole block: 4 x the quarter).
/// The block is 8 a deep and wide, so it is somewhat stiffer than the half-space Hertz assumes. Level 6 (35937
/// nodes) and level 5 use conjugate gradients.
Result<ReferenceCheck> check_hertz(const MaterialSpec& material, int level);

/// Solves a compression case for equilibrium and compares the plate force with its closed form.
Result<ReferenceCheck> check_compression(const MaterialSpec& material, int level, double strain);

/// Solves a cantilever case for equilibrium and compares the end face's mean deflection with its closed form.
Result<ReferenceCheck> check_cantilever(const MaterialSpec& material, int level);

}  // namespace palpate
