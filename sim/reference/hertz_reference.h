#pragma once
/// Hertz indentation with the contact solved (sim/contact/sphere_contact.h): a rigid sphere pressed a prescribed depth into
/// the middle of a block's top, the lattice's equilibrium found with its surface kept outside the sphere, the force
/// compared with Hertz's closed form. The pressure is not an input: it is whatever the deformation gives.

#include <cstddef>

#include "core/result.h"
#include "core/scene.h"

namespace palpate {

/// Hertz's force 4/3 E / (1 - nu^2) sqrt(R) d^(3/2) of a rigid sphere of radius R pressed d deep into a half-space (N).
double hertz_force_N(double young_modulus_Pa, double poisson_ratio, double radius_m, double depth_m);

/// The Poisson ratio the lattice of `material` represents (1/4 for springs alone, else the asked one).
double represented_poisson(const MaterialSpec& material);

/// How to sample and solve. Plain data.
struct HertzSolvedOptions {
  int samples_per_edge = 2;        ///< contact samples per cell edge of the top face (sim/contact/sphere_contact.h)
  bool iterative = false;          ///< conjugate gradients instead of LDL^T (large lattices)
  double block_side_m = 0.08;      ///< the block's width (its depth is half of it); cells block_side_m / 2^(level-1)
  bool sliding_floor = false;      ///< the floor held in z only (else fixed)
  int coarse_level = 0;            ///< > 0: graded (sim/lattice/graded_zone.h) from cells of this level far away to `level`
                                   ///< near the contact (0: uniform at `level`)
  double zone_over_contact = 1.0;  ///< the graded zone's radius (cells at `level` within it) over Hertz's sqrt(R d)
  int block_scale = 1;             ///< the block is this many times (1, 2, 4) block_side_m wide and deep; cells unchanged
};

/// What the solved indentation gives. Plain data.
struct HertzSolved {
  double force_N = 0.0;            ///< the push on the sphere, whole block (the sum of the samples' reactions)
  double closed_form_N = 0.0;      ///< Hertz's force at the prescribed depth, nu the lattice's
  double rel_error = 0.0;          ///< force_N / closed_form_N - 1
  double contact_radius_m = 0.0;   ///< farthest sample in contact from the sphere's axis (Hertz: sqrt(R d))
  double max_penetration_m = 0.0;  ///< the penalty's give: the deepest sample inside the sphere
  std::size_t nodes = 0, springs = 0;  ///< the quarter lattice solved
  std::size_t hanging = 0;         ///< its hanging nodes (graded)
  int active = 0;                  ///< samples in contact (quarter)
  int iterations = 0;              ///< Newton steps
};

/// The Hertz block of `palpate bench model` (8 x 8 x 4 cm by default, floor fixed, sides and top free) of `material` at lattice
/// `level` (>= 3; cells 8 cm / 2^(level-1); graded from options.coarse_level, the zone's radius scaled with the contact
/// radius sqrt(R d); the grid over the quarter at most 8 levels deep), a rigid sphere of radius radius_m pressed depth_m into the middle of its
/// top (its lowest point depth_m below the rest top), solved on the quarter x, y >= 0 with its symmetry planes
/// sliding (the lattice is mirror-symmetric, so this is the whole block's solution); force_N is four times the
/// quarter's. Errors name the level and depth.
Result<HertzSolved> solve_hertz_block(const MaterialSpec& material, int level, double radius_m, double depth_m,
                                      const HertzSolvedOptions& options = {});

}  // namespace palpate
