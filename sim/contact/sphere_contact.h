#pragma once
/// Contact solved under a rigid sphere: the lattice's static equilibrium with its surface kept outside the sphere
/// (frictionless, unilateral). Newton's method on the lattice's energy plus a pressure penalty on the surface
/// samples inside the sphere, (1/2) kappa A pen^2 each (pen: how far inside); the active set is the samples inside
/// at each Newton step (semi-smooth Newton), and the solve ends when that set is stable and the step is below
/// tolerance. The sphere's push is the sum of the samples' reactions: it comes from the deformation, no pressure
/// shape is assumed. The sphere's centre is either prescribed or free, held by a spring to a device position and
/// solved jointly with the lattice. Thread: any; allocates.

#include <array>
#include <cstdint>
#include <vector>

#include "core/result.h"
#include "core/types.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// A point of the object's surface as the contact sees it: the lattice nodes it moves with and its share of the
/// surface. Plain data.
struct SurfaceSample {
  std::array<int32_t, 8> node{};   ///< lattice nodes it is bound to
  std::array<double, 8> weight{};  ///< their weights (trilinear or bilinear), summing to 1
  int count = 0;                   ///< nodes used
  double area_m2 = 0.0;            ///< the surface it stands for
};

/// Samples of a lattice's boundary faces (a face of one cell only, whose four corners are not all fixed): per_edge x
/// per_edge points on each, at the centres of equal sub-squares, bilinear in the face's corners, each carrying
/// l^2 / per_edge^2 (l the cell's edge). On a refined lattice, points of such a face with a cell of another size across
/// them are inside and left out. facing (a unit axis, or zero for every face) keeps the faces whose outward normal it is.
std::vector<SurfaceSample> lattice_surface_samples(const Lattice& lat, int per_edge, const Vec3& facing = Vec3::Zero());

/// The position of sample s on the lattice at positions x_m.
Vec3 sample_position(const SurfaceSample& s, const std::vector<Vec3>& x_m);

/// The penalty stiffness per area used by default: kContactPenaltyFactor E / l (Pa/m). A patch of side l of the
/// lattice's surface has a stiffness of order E l, so a sample gives way about 1/kContactPenaltyFactor of what the
/// lattice under it does.
inline constexpr double kContactPenaltyFactor = 1e3;
double contact_penalty_Pa_per_m(double young_modulus_Pa, double cell_m);

/// How to solve. Plain data.
struct SphereContactOptions {
  double penalty_Pa_per_m = 0.0;   ///< kappa, the pressure per metre a sample is inside the sphere (> 0)
  double coupling_N_per_m = 0.0;   ///< > 0: the centre is free, held by a spring of this stiffness to device_m;
                                   ///< 0: the centre is where it is given
  Vec3 device_m = Vec3::Zero();    ///< where that spring is anchored
  int max_iterations = 60;         ///< Newton steps at most
  double step_tol_m = 1e-13;       ///< converged: the active set is stable and no DOF moved more than this in a step,
  double residual_tol_N = 1e-9;    ///< or no free DOF is out of balance by more than this
  bool iterative = false;          ///< conjugate gradients with incomplete Cholesky instead of LDL^T (large lattices)
};

/// What the contact came to. Plain data.
struct SphereContactResult {
  Vec3 force_N = Vec3::Zero();     ///< the force the surface pushes the sphere with (sum of the samples' reactions)
  Vec3 centre_m = Vec3::Zero();    ///< the sphere's centre at equilibrium (the given one when prescribed)
  int active = 0;                  ///< samples in contact
  double max_penetration_m = 0.0;  ///< the deepest sample inside the sphere (the penalty's give)
  int iterations = 0;              ///< Newton steps taken
  double max_residual_N = 0.0;     ///< largest free-DOF force imbalance at the end
};

/// Moves the free DOFs of lat->x_m (held_dof: 3n, 1 = held at x_m; empty: the fixed nodes' DOFs) to equilibrium of
/// the lattice's forces, gravity and the contact of `samples` with the sphere (centre_m, radius_m), starting from
/// lat->x_m. Velocities are left alone. Errors name the step and residual when it does not converge, or a singular
/// system (free rigid modes).
Result<SphereContactResult> solve_sphere_contact(Lattice* lat, const std::vector<uint8_t>& held_dof,
                                                 const std::vector<SurfaceSample>& samples, const Vec3& centre_m,
                                                 double radius_m, const SphereContactOptions& options);

}  // namespace palpate
