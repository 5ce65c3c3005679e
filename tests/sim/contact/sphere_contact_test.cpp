#include <cmath>

#include <gtest/gtest.h>

#include "sim/reference/hertz_reference.h"
#include "sim/reference/reference_cases.h"
#include "sim/solvers/static_solve.h"
#include "sim/contact/sphere_contact.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

// Level 5 of the 8 x 8 x 4 cm Hertz block (5 mm cells), springs (nu 1/4), the sphere R 10 cm pressed 0.25 and 1 mm:
// contact radius sqrt(R d) = 5 and 10 mm, 1 and 2 cells. The force comes from the deformation alone; measured here
// +43.8 % and +34.5 % over Hertz (the block's fixed floor and the coarse patch; docs/contact.md), exponent 1.45.
TEST(SphereContact, HertzForceFollowsTheThreeHalvesPowerLaw) {
  const MaterialSpec m = test::soft_material(0.25, MaterialModel::kSprings);
  constexpr double kR = 0.1, kD1 = 2.5e-4, kD2 = 1e-3;
  auto shallow = solve_hertz_block(m, 5, kR, kD1);
  auto deep = solve_hertz_block(m, 5, kR, kD2);
  ASSERT_TRUE(shallow) << shallow.error().message;
  ASSERT_TRUE(deep) << deep.error().message;
  const HertzSolved& a = shallow.value();
  const HertzSolved& b = deep.value();
  // the 3/2 power: F2 / F1 = (d2 / d1)^1.5 = 8
  const double exponent = std::log(b.force_N / a.force_N) / std::log(kD2 / kD1);
  EXPECT_NEAR(exponent, 1.5, 0.1) << a.force_N << " N, " << b.force_N << " N";
  // within what level 5 supports, and stiff rather than soft (the lattice under a patch one or two cells wide)
  EXPECT_GT(a.rel_error, 0.0);
  EXPECT_LT(a.rel_error, 0.5);
  EXPECT_GT(b.rel_error, 0.0);
  EXPECT_LT(b.rel_error, 0.45);
  // the patch is the deformation's, not a prescribed disc: it widens about as sqrt(d) (Hertz: twice), within a
  // sample spacing (2.5 mm) of sqrt(R d)
  EXPECT_NEAR(b.contact_radius_m / a.contact_radius_m, 2.0, 0.5);
  EXPECT_NEAR(a.contact_radius_m, std::sqrt(kR * kD1), 2.5e-3);
  EXPECT_NEAR(b.contact_radius_m, std::sqrt(kR * kD2), 2.5e-3);
  // the penalty gives a few per mille of a per cent of the depth
  EXPECT_LT(a.max_penetration_m, 1e-2 * kD1);
  EXPECT_LT(b.max_penetration_m, 1e-2 * kD2);
}

// A level-4 block (8 x 8 x 4 cm, cells of 1 cm, nu 0.45) under a sphere off its axis: the surface ends outside the
// sphere (within the penalty's give), the samples in contact on it, and the floor holds what the sphere pushes.
// With the centre free on a spring to a device position, the spring balances the contact force there, and a
// solve with the centre prescribed at that point gives the same force.
TEST(SphereContact, SurfaceConformsAndTheForcesBalance) {
  auto built = box_lattice(test::soft_material(0.45, MaterialModel::kVolumetric), 0.08, 4, {8, 8, 4});
  ASSERT_TRUE(built) << built.error().message;
  Lattice lat = std::move(built).value();
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) lat.fixed[i] = lat.rest_m[i].z() < 1e-9 ? 1 : 0;
  const double top = 0.04, radius = 0.1, depth = 2e-3;
  const auto samples = lattice_surface_samples(lat, 3);
  SphereContactOptions so;
  so.penalty_Pa_per_m = contact_penalty_Pa_per_m(1e5, lat.cell_m);
  const Vec3 centre(0.037, 0.041, top + radius - depth);
  auto r = solve_sphere_contact(&lat, {}, samples, centre, radius, so);
  ASSERT_TRUE(r) << r.error().message;
  const SphereContactResult& c = r.value();
  EXPECT_GT(c.active, 3);
  EXPECT_GT(c.force_N.z(), 0.0);
  EXPECT_LT(c.max_penetration_m, 2e-2 * depth);
  int on_sphere = 0;
  for (const SurfaceSample& s : samples) {
    const double dist = (sample_position(s, lat.x_m) - centre).norm();
    EXPECT_GT(dist, radius - c.max_penetration_m - 1e-15);
    on_sphere += dist < radius + 1e-3 * depth ? 1 : 0;
  }
  EXPECT_GE(on_sphere, c.active);
  // the floor's reaction: minus the net lattice force on the fixed nodes, equal and opposite to the push on the object
  const std::vector<Vec3> f = spring_forces_N(lat, lat.x_m);
  Vec3 floor = Vec3::Zero();
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (lat.fixed[i]) floor -= f[i];
  EXPECT_NEAR(floor.z(), c.force_N.z(), 1e-6 * c.force_N.z());
  EXPECT_NEAR(floor.x(), c.force_N.x(), 1e-6 * c.force_N.z());
  EXPECT_NEAR(floor.y(), c.force_N.y(), 1e-6 * c.force_N.z());
  // the centre free on a 300 N/m spring to a device 1 cm lower
  Lattice free_lat = lat;
  free_lat.reset_to_rest();
  SphereContactOptions fo = so;
  fo.coupling_N_per_m = 300.0;
  fo.device_m = centre - Vec3(0.0, 0.0, 1e-2);
  auto fr = solve_sphere_contact(&free_lat, {}, samples, centre + Vec3(0.0, 0.0, depth), radius, fo);
  ASSERT_TRUE(fr) << fr.error().message;
  const SphereContactResult& h = fr.value();
  EXPECT_GT(h.force_N.z(), 0.0);
  EXPECT_LT((h.force_N + fo.coupling_N_per_m * (fo.device_m - h.centre_m)).norm(), 1e-6 * h.force_N.norm());
  Lattice again = lat;
  again.reset_to_rest();
  auto pr = solve_sphere_contact(&again, {}, samples, h.centre_m, radius, so);
  ASSERT_TRUE(pr) << pr.error().message;
  EXPECT_NEAR(pr.value().force_N.z(), h.force_N.z(), 1e-4 * h.force_N.z());
}

}  // namespace
}  // namespace palpate
