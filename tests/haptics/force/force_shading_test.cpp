// Force shading: a faceted sphere is felt as the sphere it stands for (the force along the true radius at the
// device, within a few degrees, turning smoothly), a cube's faces stay flat and its edges sharp, and shading off gives
// the facets back. The patch's normals are the sim's (crease_normal over the mesh's adjacency).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>

#include "core/vertex_triangles.h"
#include "haptics/servo/servo.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kK = 300.0;  // coupling, N/m

struct Surface {
  std::vector<Vec3> v;
  std::vector<std::array<int32_t, 3>> t;
};

// a sphere of radius r in nu x nv facets (poles at +-z)
Surface faceted_sphere(double r, int nu, int nv) {
  Surface s;
  s.v.push_back(Vec3(0, 0, r));
  for (int j = 1; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double th = kPi * j / nv, ph = 2 * kPi * i / nu;
      s.v.push_back(r * Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
    }
  s.v.push_back(Vec3(0, 0, -r));
  const int south = static_cast<int>(s.v.size()) - 1;
  auto ring = [&](int j, int i) { return 1 + (j - 1) * nu + (i % nu); };
  for (int i = 0; i < nu; ++i) {
    s.t.push_back({0, ring(1, i), ring(1, i + 1)});
    for (int j = 1; j < nv - 1; ++j) {
      s.t.push_back({ring(j, i), ring(j + 1, i), ring(j + 1, i + 1)});
      s.t.push_back({ring(j, i), ring(j + 1, i + 1), ring(j, i + 1)});
    }
    s.t.push_back({ring(nv - 1, i), south, ring(nv - 1, i + 1)});
  }
  return s;
}

// an axis-aligned cube of half side h centred at the origin, two triangles a face, outward
Surface cube(double h) {
  Surface s;
  for (int i = 0; i < 8; ++i) s.v.push_back(h * Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  const int f[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : f) {
    s.t.push_back({q[0], q[1], q[2]});
    s.t.push_back({q[0], q[2], q[3]});
  }
  return s;
}

// the whole surface as the patch, with the sim's normals for crease angle crease_deg
void publish(const Surface& s, double crease_deg, TripleBuffer<LocalModel>* tb) {
  const VertexTriangles adj = VertexTriangles::build(s.v.size(), s.t);
  const double cos_crease = std::cos(crease_deg * kPi / 180.0);
  LocalModel& m = tb->write_buffer();
  m.num_triangles = 0;
  ASSERT_LE(s.t.size(), static_cast<std::size_t>(LocalModel::kMaxTriangles));
  for (int i = 0; i < static_cast<int>(s.t.size()); ++i) {
    const auto& t = s.t[i];
    m.tri_ids[m.num_triangles] = i;
    m.tri_m[m.num_triangles] = {s.v[t[0]], s.v[t[1]], s.v[t[2]]};
    for (int c = 0; c < 3; ++c) {
      m.normal[m.num_triangles][c] = crease_normal(s.v, s.v, s.t, adj, i, c, -1.0);  // the vertex normals
      m.shade_normal[m.num_triangles][c] = crease_normal(s.v, s.v, s.t, adj, i, c, cos_crease);
    }
    ++m.num_triangles;
  }
  m.frame = 0;
  tb->publish();
}

struct Stroke {
  double max_angle_deg = 0.0;   // largest angle between the force and the true normal at the device
  double p95_angle_deg = 0.0;   // its 95th percentile over the stroke's ticks
  double rms_angle_deg = 0.0;
  double worst_excess_N = 0.0;  // largest step beyond what the device's step explains
  int flips = 0;                // reversals of the force's part across the stroke
};

// the device comes in along `at(0)`'s normal, then follows at(u) for u in [0, 1] over `ticks`; normal(p) is the
// surface the facets stand for at the device
template <typename At, typename Normal>
Stroke stroke(const Surface& s, double shading_deg, double radius, At at, Normal normal, const Vec3& across,
              int ticks) {
  ServoParams p = test::static_surface_params(kK);
  p.tool_radius_m = radius;
  p.force_shading_deg = shading_deg;
  test::ServoRig<> rig(p);
  rig.dev.specs_.max_force_N = 100;
  publish(s, 60.0, rig.tb.get());
  Stroke out;
  HapticSample prev;
  double sum2 = 0.0;
  std::vector<double> angles;
  Vec3 lat_prev = Vec3::Zero();
  const int approach = 100;
  for (int i = 0; i < approach + ticks; ++i) {
    const Vec3 start = at(0.0);
    rig.dev.pos_m = i < approach ? Vec3(start + normal(start) * 0.006 * (1.0 - i / (approach - 1.0)))
                                 : at(static_cast<double>(i - approach) / ticks);
    rig.tick(i);
    const HapticSample& now = rig.servo->last_sample();
    EXPECT_EQ(now.contact, i < approach ? now.contact : ContactState::kTouch) << i;
    if (i > approach + 10) {
      const double cosang = std::clamp(now.force_N.normalized().dot(normal(now.tool_pos_m)), -1.0, 1.0);
      const double deg = std::acos(cosang) * 180.0 / kPi;
      out.max_angle_deg = std::max(out.max_angle_deg, deg);
      sum2 += deg * deg;
      angles.push_back(deg);
      if (std::getenv("TRACE") && shading_deg > 0 && radius == 0 && deg > 6) std::printf("%d %.2f |F| %.3f\n", i, deg, now.force_N.norm());
      const double dtool = (now.tool_pos_m - prev.tool_pos_m).norm();
      out.worst_excess_N = std::max(out.worst_excess_N, (now.force_N - prev.force_N).norm() - 1.2 * kK * dtool);
      const Vec3 lat = now.force_N.dot(across) * across;
      if (lat.norm() > 0.005 && lat_prev.norm() > 0.005 && lat.dot(lat_prev) < 0) ++out.flips;
      lat_prev = lat;
    }
    prev = now;
  }
  if (!angles.empty()) {
    out.rms_angle_deg = std::sqrt(sum2 / static_cast<double>(angles.size()));
    std::sort(angles.begin(), angles.end());
    out.p95_angle_deg = angles[static_cast<std::size_t>(0.95 * static_cast<double>(angles.size() - 1))];
  }
  return out;
}

TEST(ForceShading, AFacetedSphereIsFeltAsTheSphereItStandsFor) {
  // 12 x 8 facets on a 2 cm sphere (edges turn 22-30 degrees); the device 1 mm under the sphere's surface strokes
  // along a parallel at 30 degrees from the equator across 4 facets' width, at 20 mm/s; the true normal there is
  // the radius through the device
  const double big = 0.02;
  const Surface s = faceted_sphere(big, 12, 8);
  for (double radius : {0.0, 0.004}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    const double rt = big + radius - 0.001, lat = 0.52;
    auto at = [&](double u) {
      const double ph = 0.1 + u * 2.0;
      return Vec3(rt * std::cos(lat) * std::cos(ph), rt * std::cos(lat) * std::sin(ph), rt * std::sin(lat));
    };
    auto normal = [](const Vec3& p) { return Vec3(p.normalized()); };
    const int ticks = static_cast<int>(2.0 * rt * std::cos(lat) / 0.02 * 1000);
    const Vec3 across = Vec3(0, 0, 1);  // (the stroke's plane holds the force's part along it; judged for flips)
    const Stroke facets = stroke(s, 0.0, radius, at, normal, across, ticks);
    const Stroke shaded = stroke(s, 60.0, radius, at, normal, across, ticks);
    // facets: the force is the facet's normal (a point) or turns round its edges (a sphere), off the radius by up to
    // half a facet's turn; shaded, within a few degrees of it and never stepping beyond the device's motion (a point
    // rolls over each facet edge in bounded steps behind the device, a few ticks in which the turn catches up at
    // most 0.01 N a tick: its largest angle stays near the facets')
    EXPECT_GT(facets.p95_angle_deg, 8.0);
    EXPECT_LT(shaded.p95_angle_deg, 0.4 * facets.p95_angle_deg);
    EXPECT_LT(shaded.rms_angle_deg, 0.4 * facets.rms_angle_deg);
    EXPECT_LE(shaded.max_angle_deg, facets.max_angle_deg);
    EXPECT_LE(shaded.worst_excess_N, 0.02);
    EXPECT_EQ(shaded.flips, 0);
    std::printf("%s tool: facets p95 %.2f rms %.2f max %.2f deg; shaded p95 %.2f rms %.2f max %.2f deg, worst step "
                "beyond motion %.4f N\n",
                radius > 0 ? "sphere" : "point", facets.p95_angle_deg, facets.rms_angle_deg, facets.max_angle_deg,
                shaded.p95_angle_deg, shaded.rms_angle_deg, shaded.max_angle_deg, shaded.worst_excess_N);
  }
}

TEST(ForceShading, ACubesFacesStayFlatAndItsEdgesSharp) {
  // a 4 cm cube: its edges turn 90 degrees, past the 60-degree crease, so each face's normals are its own. The
  // device 1 mm under the top face strokes across it to 0.5 mm from an edge: the force is the face's normal all the
  // way, shaded or not (a cube shaded as one smooth surface would tilt it by up to 45 degrees near the edge)
  const double h = 0.02;
  const Surface s = cube(h);
  for (double radius : {0.0, 0.004}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    auto at = [&](double u) { return Vec3(-0.015 + u * 0.0345, 0.003, h + radius - 0.001); };
    auto normal = [](const Vec3&) { return Vec3(0, 0, 1); };
    const Stroke shaded = stroke(s, 60.0, radius, at, normal, Vec3(1, 0, 0), 1700);
    EXPECT_LT(shaded.max_angle_deg, 1e-6);
  }
}

// the servo's samples over `ticks` with the device at path(i); the surface published with crease normals of 60 degrees
template <typename Path>
std::vector<HapticSample> run(const Surface& s, const ServoParams& p, Path path, int ticks) {
  test::ServoRig<> rig(p);
  rig.dev.specs_.max_force_N = 100;
  publish(s, 60.0, rig.tb.get());
  std::vector<HapticSample> out;
  for (int i = 0; i < ticks; ++i) {
    rig.dev.pos_m = path(i);
    rig.tick(i);
    out.push_back(rig.servo->last_sample());
  }
  return out;
}

TEST(ForceShading, RoundASharpEdgeTheForceTurnsWithTheFacetsPush) {
  // a 4 mm sphere pressed 1 mm onto a cube's 90-degree edge and rolled round it from the top face to the side in
  // 30 ms: past the crease the shaded normal is the facets' push, and the force follows it as fast as it turns (a
  // force that turned at its 5 mN a tick instead lagged the push by tens of degrees, pushing the hand the wrong way)
  const double h = 0.02, r = 0.004, arm = r - 0.001;
  const Surface s = cube(h);
  ServoParams p = test::static_surface_params(kK);
  p.tool_radius_m = r;
  p.force_shading_deg = 60.0;
  auto path = [&](int i) {
    const Vec3 edge(h, 0.003, h);
    if (i < 300) return Vec3(edge + Vec3(-0.006 * (1.0 - i / 299.0), 0.0, arm + 0.003 * std::max(0.0, 1.0 - i / 100.0)));
    const double phi = 0.5 * kPi * std::min(1.0, (i - 300) / 30.0);
    return Vec3(edge + arm * Vec3(std::sin(phi), 0.0, std::cos(phi)));
  };
  const auto samples = run(s, p, path, 450);
  double worst_deg = 0.0;
  for (std::size_t i = 320; i < samples.size(); ++i) {
    const HapticSample& x = samples[i];
    ASSERT_EQ(x.contact, ContactState::kTouch) << i;
    const Vec3 push = (x.proxy_pos_m - x.tool_pos_m).normalized();
    worst_deg = std::max(worst_deg, std::acos(std::clamp(x.force_N.normalized().dot(push), -1.0, 1.0)) * 180.0 / kPi);
  }
  EXPECT_LT(worst_deg, 3.0);  // (66 degrees when it turned at 5 mN a tick)
}

TEST(ForceShading, FrictionKeepsItsCoefficientsWhenShaded) {
  // friction on a shaded face: the force across it at breakaway is mu_s times the force along its normal, as on
  // facets (the shading is taken from a companion proxy without friction: from the held proxy itself, the friction's
  // pull across read as the surface's tilt and was turned away)
  Surface s;
  const double h = 0.05;
  s.v = {{-h, -h, 0.0}, {h, -h, 0.0}, {h, h, 0.0}, {-h, h, 0.0}};
  s.t = {{0, 1, 2}, {0, 2, 3}};
  ServoParams p = test::static_surface_params(kK);
  p.force_shading_deg = 60.0;
  p.friction.static_coefficient = 0.6;
  p.friction.dynamic_coefficient = 0.4;
  auto path = [](int i) {  // pressed 2 mm, then pulled across at 10 mm/s
    return Vec3(i < 300 ? 0.0 : 1e-5 * (i - 300), 0.001, 0.002 - std::min(1.0, i / 100.0) * 0.004);
  };
  const auto samples = run(s, p, path, 900);
  double breakaway = 0.0;
  std::size_t slip = 0;
  for (std::size_t i = 300; i < samples.size() && slip == 0; ++i) {
    if ((samples[i].proxy_pos_m - samples[i - 1].proxy_pos_m).norm() > 1e-12) slip = i;
    else breakaway = std::max(breakaway, -samples[i].force_N.x());
  }
  ASSERT_GT(slip, 0u);
  const double normal = samples[299].force_N.z();
  EXPECT_NEAR(normal, kK * 0.002, 1e-6);
  EXPECT_NEAR(breakaway, 0.6 * normal, 0.03 * 0.6 * normal);
  // and sliding, mu_d times the normal force in the face's frame
  for (std::size_t i = slip + 100; i < samples.size(); ++i)
    EXPECT_NEAR(-samples[i].force_N.x() / samples[i].force_N.z(), 0.4, 0.02) << i;
}

}  // namespace
}  // namespace palpate
