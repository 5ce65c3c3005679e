// Contact solved under the tool, frame by frame (sim/contact/solved_contact.h): the complementarity problem against a case
// worked by hand, and on a block the surface the solved load deforms meeting the sphere where it carries the push
// and nowhere inside it.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/contact/solved_contact.h"
#include "sim/contact_block.h"

namespace palpate {
namespace {

// Two points, each on its own spring (compliances c1, c2), the second h farther from the sphere: the first carries
// the whole push until the sphere has moved h, then both share it.
TEST(SolvedContact, TwoPointsTouchInTurnAsThePushGrows) {
  const double c1 = 2e-3, c2 = 5e-3, h = 1e-3;
  Eigen::MatrixXd c(2, 2);
  c << c1, 0, 0, c2;
  Eigen::VectorXd g(2), a(2);
  g << 0.0, h;
  a << 1.0, 1.0;
  ContactLcpResult r;
  // 0.4 N moves the first point 0.8 mm: the second is still 0.2 mm away
  ASSERT_TRUE(solve_contact_lcp(c, g, a, 0.4, 0.0, &r));
  EXPECT_EQ(r.active, 1);
  EXPECT_NEAR(r.p[0], 0.4, 1e-12);
  EXPECT_EQ(r.p[1], 0.0);
  EXPECT_NEAR(r.delta_m, 0.4 * c1, 1e-15);
  // 1 N: the sphere moves delta = (F + h / c2) / (1 / c1 + 1 / c2) and each point carries delta' / c
  ASSERT_TRUE(solve_contact_lcp(c, g, a, 1.0, 0.0, &r));
  const double delta = (1.0 + h / c2) / (1.0 / c1 + 1.0 / c2);
  EXPECT_EQ(r.active, 2);
  EXPECT_NEAR(r.delta_m, delta, 1e-15);
  EXPECT_NEAR(r.p[0], delta / c1, 1e-12);
  EXPECT_NEAR(r.p[1], (delta - h) / c2, 1e-12);
  // nothing faces the push, or no push: no solution
  a << -1.0, 0.05;
  EXPECT_FALSE(solve_contact_lcp(c, g, a, 1.0, 0.0, &r));
  a << 1.0, 1.0;
  EXPECT_FALSE(solve_contact_lcp(c, g, a, 0.0, 0.0, &r));
}

// The mesh of `b` moved by the lattice displacement u (each vertex by its corner's point weights).
std::vector<Vec3> deformed(const test::ContactBlock& b, const std::vector<Vec3>& u) {
  std::vector<Vec3> x = b.box.mesh.vertices_m;
  std::vector<uint8_t> done(x.size(), 0);
  for (std::size_t t = 0; t < b.box.mesh.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const auto v = static_cast<std::size_t>(b.box.mesh.triangles[t][k]);
      if (done[v]) continue;
      done[v] = 1;
      const PointWeights w = point_weights(b.lat, b.rest, static_cast<int32_t>(t), Vec3::Unit(k));
      for (int i = 0; i < w.count; ++i) x[v] += w.weight[i] * u[static_cast<std::size_t>(w.node[i])];
    }
  return x;
}

struct Press {
  test::ContactBlock b{4, 32};  // cells of 1 cm, quads of 2.5 mm
  ContactCompliance compliance;
  std::vector<int32_t> tris;
  static constexpr double kRadius_m = 0.1;  // pressed 4-5 mm: a contact radius of about two cells
  const Vec3 centre{0.003, -0.002, 0.04 + kRadius_m};  // resting on the top face
  Vec3 push_N = Vec3::Zero();

  Press() {
    for (std::size_t t = 0; t < b.box.mesh.triangles.size(); ++t) tris.push_back(static_cast<int32_t>(t));
    // the factor, and a push that would move the point under the sphere 8 mm as a point load
    const PointWeights point = point_weights(b.lat, b.rest, b.top_triangle(centre.x(), centre.y()), Vec3::Constant(1.0 / 3));
    Mat3 c;
    EXPECT_TRUE(compliance.compute(b.lat, point, false, &c));
    push_N = Vec3(0, 0, -8e-3 / c(2, 2));
  }
  // the lattice's static displacement under the push spread by w
  std::vector<Vec3> displacement(const PointWeights& w) {
    std::vector<Vec3> f(b.lat.num_nodes(), Vec3::Zero()), u;
    for (int i = 0; i < w.count; ++i) f[static_cast<std::size_t>(w.node[i])] += w.weight[i] * push_N;
    EXPECT_TRUE(compliance.solve(f, &u));
    return u;
  }
};

TEST(SolvedContact, TheLoadedSurfaceMeetsTheSphereWhereItIsPushedAndNowhereInsideIt) {
  Press s;
  SolvedContactLoad load;
  PointWeights w;
  ASSERT_TRUE(load.weights(s.b.lat, s.b.rest, s.b.box.mesh.vertices_m, s.tris, s.centre, Press::kRadius_m, s.push_N,
                           &s.compliance, &w));
  double sum = 0.0;
  Vec3 at = Vec3::Zero();
  for (int i = 0; i < w.count; ++i) sum += w.weight[i], at += w.weight[i] * s.b.lat.rest_m[static_cast<std::size_t>(w.node[i])];
  EXPECT_NEAR(sum, 1.0, 1e-9);
  // spread over a patch, centred under the sphere (within a quarter of a sample's spacing)
  const SolvedContactReport& rep = load.report();
  EXPECT_GE(rep.active, 7);
  EXPECT_GT(rep.contact_radius_m, 0.5 * s.b.lat.cell_m);
  EXPECT_LT(std::hypot(at.x() - s.centre.x(), at.y() - s.centre.y()), 0.25 * rep.contact_radius_m);
  // the sphere, moved by delta, touches the deformed top where the load is and nothing of it is inside
  const std::vector<Vec3> x = deformed(s.b, s.displacement(w));
  const Vec3 moved = s.centre + Vec3(0, 0, -rep.delta_m);
  double inside = 0.0, touching_gap = 0.0;
  int touching = 0;
  for (std::size_t v = 0; v < x.size(); ++v) {
    if (std::abs(s.b.box.mesh.vertices_m[v].z() - 0.04) > 1e-12) continue;
    const double gap = (x[v] - moved).norm() - Press::kRadius_m;
    inside = std::max(inside, -gap);
    const Vec3 d = x[v] - moved;
    if (std::hypot(d.x(), d.y()) < 0.6 * rep.contact_radius_m) touching_gap = std::max(touching_gap, std::abs(gap)), ++touching;
  }
  EXPECT_GT(rep.delta_m, 5e-4);
  EXPECT_GE(touching, 4);
  // within what a bilinear cell face can follow of the sphere: the paraboloid r^2 / 2R across a face of side l departs
  // from its corners' interpolation by up to l^2 / 4R in the middle
  const double follow = s.b.lat.cell_m * s.b.lat.cell_m / (4.0 * Press::kRadius_m);
  EXPECT_LT(inside, follow + 0.01 * rep.delta_m);
  EXPECT_LT(touching_gap, follow + 0.01 * rep.delta_m);
}

// Frame after frame with the surface already carrying the load: the same load again (the dimple is not pushed twice).
TEST(SolvedContact, ASurfaceAlreadyCarryingTheLoadGetsTheSameLoad) {
  Press s;
  SolvedContactLoad load;
  PointWeights first, again;
  ASSERT_TRUE(load.weights(s.b.lat, s.b.rest, s.b.box.mesh.vertices_m, s.tris, s.centre, Press::kRadius_m, s.push_N,
                           &s.compliance, &first));
  const double delta = load.report().delta_m;
  // the surface deformed by it, and the sphere where it then rests
  const std::vector<Vec3> x = deformed(s.b, s.displacement(first));
  const Vec3 resting = s.centre + Vec3(0, 0, -delta);
  ASSERT_TRUE(load.weights(s.b.lat, s.b.rest, x, s.tris, resting, Press::kRadius_m, s.push_N, &s.compliance, &again));
  EXPECT_NEAR(load.report().delta_m, 0.0, 0.02 * delta);
  std::vector<double> a(s.b.lat.num_nodes(), 0.0), b(a.size(), 0.0);
  for (int i = 0; i < first.count; ++i) a[static_cast<std::size_t>(first.node[i])] += first.weight[i];
  for (int i = 0; i < again.count; ++i) b[static_cast<std::size_t>(again.node[i])] += again.weight[i];
  double moved = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) moved += std::abs(a[i] - b[i]);
  EXPECT_LT(moved, 0.05);  // of the total weight 1 (2 would be a wholly different load)
}

// A part of the model overhanging the sphere (an ear above the tool pressing the back under it) faces the push too,
// but lies behind the sphere: only the surface in front of it is sampled. (Taken as nearest the sphere, the ear was
// loaded and pulled down 4 cm onto the tool.)
TEST(SolvedContact, AnOverhangBehindTheSphereIsNotWhatItMeets) {
  const double r = 0.006;
  // two squares 2 cm wide facing up: the surface pressed at z = 0 and the overhang at z = 2 cm, above the sphere
  std::vector<Vec3> v;
  std::vector<std::array<int32_t, 3>> tris;
  for (double z : {0.0, 0.02}) {
    const auto base = static_cast<int32_t>(v.size());
    for (const auto& [x, y] : {std::pair{-0.01, -0.01}, {0.01, -0.01}, {0.01, 0.01}, {-0.01, 0.01}}) v.emplace_back(x, y, z);
    tris.push_back({base, base + 1, base + 2});
    tris.push_back({base, base + 2, base + 3});
  }
  const std::vector<int32_t> all{0, 1, 2, 3};
  std::vector<ContactPoint> points;
  contact_points(v, tris, all, Vec3(0, 0, r), Vec3(0, 0, -1), r, 0.004, 0.001, 48, &points);
  ASSERT_GE(points.size(), 30u);
  for (const ContactPoint& p : points) EXPECT_LT(p.tri, 2) << "a point of the overhang";
  // the surface just inside the sphere (pressed 1 mm) is still met
  contact_points(v, tris, all, Vec3(0, 0, r - 1e-3), Vec3(0, 0, -1), r, 0.004, 0.001, 48, &points);
  ASSERT_GE(points.size(), 30u);
  for (const ContactPoint& p : points) EXPECT_LT(p.tri, 2);
}

}  // namespace
}  // namespace palpate
