// The static solve and the solved sphere contact on a graded lattice (hanging nodes eliminated, sim/solvers/free_coords.h):
// uniform compression gives the uniform lattice's force and keeps the hanging nodes on their faces; a sphere pressed
// where the graded lattice is as fine as a uniform one gives that lattice's force; the surface samples of a graded
// lattice cover its surface once; the graded Hertz block names a bad block scale or coarse level.
#include "sim/solvers/free_coords.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "sim/contact/contact_compliance.h"
#include "sim/lattice/forces.h"
#include "sim/lattice/graded_zone.h"
#include "sim/lattice/hanging.h"
#include "sim/reference/hertz_reference.h"
#include "sim/lattice/refined_lattice.h"
#include "sim/contact/sphere_contact.h"
#include "sim/solvers/static_solve.h"
#include "support/fixtures.h"

namespace palpate {
namespace {

// The 4 cm box (grid centred at the origin), level 2 (2 cm) far away, level 4 (5 mm) near the top's centre.
constexpr double kSide_m = 0.04;
constexpr int kCoarse = 2, kFine = 4;
const Vec3 kTop(0.0, 0.0, 0.5 * kSide_m);

LatticeSpec spec_at(int level) {
  LatticeSpec s;
  s.level = level;
  s.radius_cells = 64;
  s.material = test::soft_material();
  s.material.density_kg_per_m3 = 1000.0;
  return s;
}

// Graded to kFine within radius_m of the top's centre, or uniform at kFine (radius_m 0).
Lattice box(const test::BoxModel& b, double radius_m) {
  const int level = radius_m > 0.0 ? kCoarse : kFine;
  const auto cells = region_cells(b.grid, level, {0, 0, 0}, 64);
  auto built = radius_m > 0.0 ? build_refined_lattice(b.grid, spec_at(level), cells, kFine,
                                                       graded_leaves(b.grid, level, cells, kFine, kTop, radius_m))
                              : build_lattice(b.grid, spec_at(level), cells);
  EXPECT_TRUE(built) << built.error().message;
  Lattice lat = std::move(built).value();
  std::fill(lat.fixed.begin(), lat.fixed.end(), 0);
  return lat;
}

// Held DOFs: the floor in z, the planes x = -s/2 and y = -s/2 in their normal (sliding), the top in z.
std::vector<uint8_t> sliding_box(const Lattice& lat) {
  std::vector<uint8_t> held(3 * lat.num_nodes(), 0);
  const double lo = -0.5 * kSide_m + 1e-9, hi = 0.5 * kSide_m - 1e-9;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    const Vec3& p = lat.rest_m[i];
    if (p.x() < lo) held[3 * i] = 1;
    if (p.y() < lo) held[3 * i + 1] = 1;
    if (p.z() < lo || p.z() > hi) held[3 * i + 2] = 1;
  }
  return held;
}

// The top pressed strain * side down (floor and two sides sliding): the force on the top plates (N).
double compressed_top_force_N(Lattice* lat, double strain) {
  for (std::size_t i = 0; i < lat->num_nodes(); ++i)
    if (lat->rest_m[i].z() > 0.5 * kSide_m - 1e-9) lat->x_m[i].z() -= strain * kSide_m;
  auto r = solve_static(lat, sliding_box(*lat), {});
  EXPECT_TRUE(r) << r.error().message;
  std::vector<Vec3> f = spring_forces_N(*lat, lat->x_m);
  fold_hanging(*lat, &f);
  double top_N = 0.0;
  for (std::size_t i = 0; i < lat->num_nodes(); ++i)
    if (lat->rest_m[i].z() > 0.5 * kSide_m - 1e-9) top_N += f[i].z();
  return top_N;
}

TEST(GradedStatic, UniformCompressionGivesTheUniformLatticesForceWithHangingNodesOnTheirFaces) {
  const auto b = test::make_box_model(kSide_m, kFine);
  Lattice graded = box(b, 8e-3), uniform = box(b, 0.0);
  ASSERT_FALSE(graded.hanging.empty());
  ASSERT_TRUE(uniform.hanging.empty());
  const double strain = 1e-3;
  const double f_uniform = compressed_top_force_N(&uniform, strain), f_graded = compressed_top_force_N(&graded, strain);
  // the springs' solid under uniaxial stress: E A strain
  EXPECT_NEAR(f_uniform, 1e5 * kSide_m * kSide_m * strain, 1e-3 * f_uniform);
  EXPECT_NEAR(f_graded, f_uniform, 1e-6 * f_uniform);
  for (const HangingNode& h : graded.hanging) {
    Vec3 on_face = Vec3::Zero();
    for (int k = 0; k < h.count; ++k)
      on_face += h.weight[static_cast<std::size_t>(k)] * graded.x_m[static_cast<std::size_t>(h.master[static_cast<std::size_t>(k)])];
    EXPECT_LT((graded.x_m[static_cast<std::size_t>(h.node)] - on_face).norm(), 1e-15);
  }
}

TEST(GradedStatic, SphereOnTheFineZoneGivesTheUniformFineLatticesForce) {
  const auto b = test::make_box_model(kSide_m, kFine);
  // R 4 cm pressed 1 mm: contact radius about 6 mm, inside the 12 mm zone of 5 mm cells
  const double radius = 0.04, depth = 1e-3;
  const Vec3 centre = kTop + Vec3(0.0, 0.0, radius - depth);
  auto press = [&](Lattice lat) {
    std::vector<uint8_t> held(3 * lat.num_nodes(), 0);
    for (std::size_t i = 0; i < lat.num_nodes(); ++i)
      if (lat.rest_m[i].z() < -0.5 * kSide_m + 1e-9) held[3 * i] = held[3 * i + 1] = held[3 * i + 2] = 1;
    SphereContactOptions so;
    so.penalty_Pa_per_m = contact_penalty_Pa_per_m(1e5, lat.cell_m);
    auto r = solve_sphere_contact(&lat, held, lattice_surface_samples(lat, 2, Vec3::UnitZ()), centre, radius, so);
    EXPECT_TRUE(r) << r.error().message;
    return r ? r.value().force_N.z() : 0.0;
  };
  const double f_uniform = press(box(b, 0.0)), f_graded = press(box(b, 12e-3));
  EXPECT_GT(f_uniform, 0.0);
  EXPECT_NEAR(f_graded, f_uniform, 0.02 * f_uniform);
}

// The contact compliance (the servo's and the solved contact's factor) on a graded lattice: its hanging nodes move
// with their masters, so a point load's compliance and the displacement K^-1 f equal the static solve's.
TEST(GradedStatic, TheContactComplianceFollowsTheHangingNodesAsTheStaticSolveDoes) {
  const auto b = test::make_box_model(kSide_m, kFine);
  Lattice lat = box(b, 8e-3);
  ASSERT_FALSE(lat.hanging.empty());
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) lat.fixed[i] = lat.rest_m[i].z() < -0.5 * kSide_m + 1e-9;
  lat.gravity_m_per_s2 = Vec3::Zero();
  lat.touch();
  // a load on a hanging node and one on a free node of the top
  std::size_t hanging_top = lat.num_nodes(), free_top = lat.num_nodes();
  std::vector<uint8_t> hangs(lat.num_nodes(), 0);
  for (const HangingNode& h : lat.hanging) hangs[static_cast<std::size_t>(h.node)] = 1;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    if (lat.rest_m[i].z() > kTop.z() - 1e-9) (hangs[i] ? hanging_top : free_top) = i;
  ASSERT_LT(hanging_top, lat.num_nodes());
  ASSERT_LT(free_top, lat.num_nodes());
  PointWeights w;
  w.add(static_cast<int32_t>(hanging_top), 0.5);
  w.add(static_cast<int32_t>(free_top), 0.5);
  const Vec3 f(1e-4, -2e-4, -1e-3);  // small: the static solve is nonlinear, the factor the tangent at rest
  std::vector<Vec3> load(lat.num_nodes(), Vec3::Zero());
  load[hanging_top] += 0.5 * f;
  load[free_top] += 0.5 * f;
  ContactCompliance cc;
  Mat3 c;
  ASSERT_TRUE(cc.compute(lat, w, false, &c));
  std::vector<Vec3> u;
  ASSERT_TRUE(cc.solve(load, &u));
  // the static solve, linear at this load
  Lattice solved = lat;
  ASSERT_TRUE(solve_static(&solved, {}, load));
  Vec3 moved = Vec3::Zero();
  double worst = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    worst = std::max(worst, (u[i] - (solved.x_m[i] - lat.x_m[i])).norm());
    largest = std::max(largest, u[i].norm());
  }
  for (int i = 0; i < w.count; ++i) moved += w.weight[i] * u[static_cast<std::size_t>(w.node[i])];
  EXPECT_GT(largest, 1e-9);
  EXPECT_LT(worst, 1e-3 * largest);
  EXPECT_LT((c * f - moved).norm(), 1e-9 * moved.norm());
}

TEST(GradedStatic, SurfaceSamplesCoverTheSurfaceOnce) {
  const auto b = test::make_box_model(kSide_m, kFine);
  const Lattice graded = box(b, 8e-3);
  double all_m2 = 0.0, top_m2 = 0.0;
  std::size_t fine_top = 0;
  for (const SurfaceSample& s : lattice_surface_samples(graded, 1)) all_m2 += s.area_m2;
  for (const SurfaceSample& s : lattice_surface_samples(graded, 1, Vec3::UnitZ())) {
    top_m2 += s.area_m2;
    EXPECT_NEAR(sample_position(s, graded.rest_m).z(), kTop.z(), 1e-12);
    fine_top += std::abs(s.area_m2 - graded.cell_m * graded.cell_m) < 1e-12;
  }
  EXPECT_NEAR(all_m2, 6.0 * kSide_m * kSide_m, 1e-12);
  EXPECT_NEAR(top_m2, kSide_m * kSide_m, 1e-12);
  EXPECT_GT(fine_top, 0u);
}

TEST(GradedStatic, HertzBlockNamesABadScaleOrCoarseLevel) {
  MaterialSpec m = spec_at(kFine).material;
  HertzSolvedOptions o;
  o.block_scale = 3;
  auto r = solve_hertz_block(m, 5, 0.1, 2.5e-4, o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("block scale 3 is not 1, 2 or 4"), std::string::npos) << r.error().message;
  o.block_scale = 1;
  o.coarse_level = 6;
  r = solve_hertz_block(m, 5, 0.1, 2.5e-4, o);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("coarse level 6 is not in [2, 5]"), std::string::npos) << r.error().message;
}

}  // namespace
}  // namespace palpate
