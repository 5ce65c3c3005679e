// The god-object settles: with a still device the point and sphere proxies come to one position on a face, a
// convex edge, a vertex, a concave crease and a dent of the bunny (scenes/bunny.obj), and on a slow stroke over a
// faceted sphere and across convex edges of the bunny they move per tick no more than the device's motion explains.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>

#include "core/mesh_io.h"
#include "core/tri_mesh.h"
#include "haptics/servo/servo.h"
#include "support/fixtures.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kK = 300.0;  // coupling, N/m

struct Surface {
  std::vector<Vec3> v, n;
  std::vector<std::array<int32_t, 3>> t;
};

// the bunny scaled to 10 cm, centred
const Surface& bunny() {
  static const Surface s = [] {
    auto mesh = load_mesh(test::source_path("scenes/bunny.obj"));
    EXPECT_TRUE(mesh.ok());
    Surface out;
    if (!mesh.ok()) return out;
    Vec3 lo = Vec3::Constant(INFINITY), hi = -lo;
    for (const Vec3& p : mesh.value().vertices_m) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const double scale = 0.1 / (hi - lo).maxCoeff();
    for (const Vec3& p : mesh.value().vertices_m) out.v.push_back((p - 0.5 * (lo + hi)) * scale);
    out.t = mesh.value().triangles;
    compute_vertex_normals(out.v, out.t, &out.n);
    return out;
  }();
  return s;
}

Vec3 face_normal(const Surface& s, int i) {
  const auto& t = s.t[i];
  return (s.v[t[1]] - s.v[t[0]]).cross(s.v[t[2]] - s.v[t[0]]).normalized();
}

// the patch the sim would publish: the triangles nearest `at`
void publish(const Surface& s, const Vec3& at, TripleBuffer<LocalModel>* tb) {
  std::vector<int> order(s.t.size());
  std::iota(order.begin(), order.end(), 0);
  auto dist = [&](int i) { return ((s.v[s.t[i][0]] + s.v[s.t[i][1]] + s.v[s.t[i][2]]) / 3.0 - at).squaredNorm(); };
  const std::size_t keep = std::min<std::size_t>(order.size(), LocalModel::kMaxTriangles);
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(keep), order.end(),
                    [&](int a, int b) { return dist(a) < dist(b); });
  LocalModel& m = tb->write_buffer();
  m.num_triangles = 0;
  for (std::size_t k = 0; k < keep; ++k) {
    const auto& t = s.t[order[k]];
    m.tri_ids[m.num_triangles] = order[k];
    m.tri_m[m.num_triangles] = {s.v[t[0]], s.v[t[1]], s.v[t[2]]};
    m.normal[m.num_triangles] = {s.n[t[0]], s.n[t[1]], s.n[t[2]]};
    ++m.num_triangles;
  }
  m.frame = 0;
  tb->publish();
}

struct Run {
  double max_still_move_m = 0.0;   // largest proxy move per tick while the device is still
  double max_still_step_N = 0.0;   // largest force step per tick while the device is still
  int contact_ticks = 0;
};

// the device comes in along -dir to `depth` past `site` (the tool's centre `radius` further out), then holds
Run press_and_hold(const Surface& s, const Vec3& site, const Vec3& dir, double radius, double depth) {
  ServoParams p = test::static_surface_params(kK);
  p.tool_radius_m = radius;
  test::ServoRig<> rig(p);
  rig.dev.specs_.max_force_N = 100;
  publish(s, site, rig.tb.get());
  const Vec3 out = site + dir * (radius + 0.003), in = site + dir * (radius - depth);
  Run run;
  HapticSample prev;
  for (int i = 0; i < 400; ++i) {
    rig.dev.pos_m = out + std::min(1.0, i / 100.0) * (in - out);
    rig.tick(i);
    const HapticSample& now = rig.servo->last_sample();
    run.contact_ticks += now.contact == ContactState::kTouch;
    if (i > 150) {
      run.max_still_move_m = std::max(run.max_still_move_m, (now.proxy_pos_m - prev.proxy_pos_m).norm());
      run.max_still_step_N = std::max(run.max_still_step_N, (now.force_N - prev.force_N).norm());
    }
    prev = now;
  }
  return run;
}

// edges of the bunny whose faces turn by at least min_deg, convex or concave (the first `count` found, give or take
// a face's other edges): the edge's ends and the two faces' normals
struct Edge {
  Vec3 a, b, na, nb;
};
std::vector<Edge> sharp_edges(const Surface& s, double min_deg, bool convex, std::size_t count) {
  std::map<std::pair<int, int>, int> first;
  std::vector<Edge> out;
  for (int i = 0; i < static_cast<int>(s.t.size()) && out.size() < count; ++i)
    for (int k = 0; k < 3; ++k) {
      const int a = s.t[i][k], b = s.t[i][(k + 1) % 3];
      const auto key = std::make_pair(std::min(a, b), std::max(a, b));
      const auto it = first.find(key);
      if (it == first.end()) {
        first[key] = i;
        continue;
      }
      const int j = it->second;
      const Vec3 ni = face_normal(s, i), nj = face_normal(s, j);
      if (ni.dot(nj) > std::cos(min_deg * kPi / 180)) continue;
      int opp = -1;  // j's corner off the edge
      for (int c : s.t[j])
        if (c != a && c != b) opp = c;
      if (((s.v[opp] - s.v[a]).dot(ni) < 0.0) != convex) continue;
      out.push_back({s.v[a], s.v[b], nj, ni});
    }
  return out;
}

// the first such edge: its middle, and *dir the faces' mean normal
bool find_edge(const Surface& s, bool convex, double min_deg, Vec3* mid, Vec3* dir) {
  const std::vector<Edge> edges = sharp_edges(s, min_deg, convex, 1);
  if (edges.empty()) return false;
  *mid = 0.5 * (edges.front().a + edges.front().b);
  *dir = (edges.front().na + edges.front().nb).normalized();
  return true;
}

std::vector<Edge> convex_edges(const Surface& s, double min_deg, std::size_t count) {
  return sharp_edges(s, min_deg, true, count);
}

void expect_settles(const Run& r, const char* where) {
  EXPECT_GT(r.contact_ticks, 250) << where;
  EXPECT_LE(r.max_still_move_m, 1e-9) << where;
  EXPECT_LE(r.max_still_step_N, 1e-6) << where;
}

TEST(ProxySettle, StillDeviceOnAFaceAnEdgeAVertexAndACreaseOfTheBunny) {
  const Surface& s = bunny();
  ASSERT_FALSE(s.t.empty());
  Vec3 edge, edge_dir, crease, crease_dir;
  ASSERT_TRUE(find_edge(s, true, 30.0, &edge, &edge_dir));
  ASSERT_TRUE(find_edge(s, false, 30.0, &crease, &crease_dir));
  // a face: the first whose normal points up; a vertex: the one with the most turned normals round it
  int face = 0;
  while (face_normal(s, face).z() < 0.9) ++face;
  const auto& ft = s.t[face];
  const Vec3 face_site = (s.v[ft[0]] + s.v[ft[1]] + s.v[ft[2]]) / 3.0;
  std::vector<double> spread(s.v.size(), 1.0);
  for (int i = 0; i < static_cast<int>(s.t.size()); ++i)
    for (int c : s.t[i]) spread[c] = std::min(spread[c], face_normal(s, i).dot(s.n[c]));
  const int vertex = static_cast<int>(std::min_element(spread.begin(), spread.end()) - spread.begin());
  for (double radius : {0.0, 0.004}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    expect_settles(press_and_hold(s, face_site, face_normal(s, face), radius, 0.001), "face");
    expect_settles(press_and_hold(s, edge, edge_dir, radius, 0.001), "convex edge");
    expect_settles(press_and_hold(s, s.v[vertex], s.n[vertex], radius, 0.001), "vertex");
    expect_settles(press_and_hold(s, crease, crease_dir, radius, 0.001), "concave crease");
  }
}

TEST(ProxySettle, SlowStrokeAcrossConvexEdgesOfTheBunnyMovesOnlyAsTheDeviceDoes) {
  // the device (a point, or a 4 mm sphere's centre) 1 mm into the surface at the edge strokes at 20 mm/s straight
  // across convex edges of the bunny (faces turned by 25 degrees or more), 1.5 mm either side. No jump limit: the proxy
  // alone keeps each tick's force step within what the device's step explains (k |dx|) plus 0.02 N (a point pressed
  // 1 mm in used to snap over such an edge in one tick: 0.15-0.19 N), and the force's part across the edge turns
  // from the first face's side to the second's once, never back.
  const Surface& s = bunny();
  ASSERT_FALSE(s.t.empty());
  const std::vector<Edge> edges = convex_edges(s, 25.0, 6);
  ASSERT_EQ(edges.size(), 6u);
  const double depth = 0.001, leg = 0.0015, step = 2e-5;
  for (double radius : {0.0, 0.004}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    for (const Edge& e : edges) {
      const Vec3 mid = 0.5 * (e.a + e.b), along = (e.b - e.a).normalized();
      // a straight stroke across the edge, square to it, parallel to the plane half way between the faces
      const Vec3 n = (e.na + e.nb).normalized();
      const Vec3 t = along.cross(n) * (along.cross(n).dot(e.na) < 0 ? 1.0 : -1.0);  // from the first face's side
      auto at = [&](double u) -> Vec3 { return mid + (u - leg) * t - (depth - radius) * n; };
      ServoParams p = test::static_surface_params(kK);
      p.tool_radius_m = radius;
      test::ServoRig<> rig(p);
      rig.dev.specs_.max_force_N = 100;
      publish(s, mid, rig.tb.get());
      const Vec3 start = at(0.0), out = start + n * (radius + 0.003);
      const int approach = 100, ticks = approach + 50 + static_cast<int>(2 * leg / step);
      HapticSample prev;
      double worst_excess_N = 0.0;
      int flips = 0, contact = 0;
      Vec3 lat_prev = Vec3::Zero();
      const Vec3 across = (e.na - e.nb).normalized();
      for (int i = 0; i < ticks; ++i) {
        rig.dev.pos_m = i < approach ? Vec3(out + (start - out) * (i / (approach - 1.0)))
                                     : at(step * std::max(0, i - approach - 50));
        rig.tick(i);
        const HapticSample& now = rig.servo->last_sample();
        if (i >= approach) {
          contact += now.contact == ContactState::kTouch;
          const double dtool = (now.tool_pos_m - prev.tool_pos_m).norm();
          worst_excess_N = std::max(worst_excess_N, (now.force_N - prev.force_N).norm() - kK * dtool);
          const Vec3 lat = now.force_N.dot(across) * across;
          if (lat.norm() > 0.005 && lat_prev.norm() > 0.005 && lat.dot(lat_prev) < 0) ++flips;
          lat_prev = lat;
        }
        prev = now;
      }
      EXPECT_EQ(contact, ticks - approach);
      EXPECT_LE(worst_excess_N, 0.02);
      EXPECT_LE(flips, 1);
    }
  }
}

TEST(ProxySettle, StillSphereInTheDentALatticeMakesUnderIt) {
  // the bunny's back pressed in 2 mm by a smooth dent 4 mm wide, as the lattice deforms under a 5 mm sphere
  Surface s = bunny();
  ASSERT_FALSE(s.t.empty());
  int top = 0;
  for (int i = 0; i < static_cast<int>(s.v.size()); ++i)
    if (s.v[i].z() > s.v[top].z()) top = i;
  const Vec3 centre = s.v[top], down = -s.n[top];
  for (Vec3& p : s.v) p += 0.002 * std::exp(-(p - centre).squaredNorm() / (0.004 * 0.004)) * down;
  compute_vertex_normals(s.v, s.t, &s.n);
  const Vec3 site = centre + 0.002 * down;
  for (double radius : {0.0, 0.005}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    expect_settles(press_and_hold(s, site, -down, radius, 0.0015), "dent");
  }
}

TEST(ProxySettle, SlowStrokeOverAFacetedSphereMovesOnlyAsTheDeviceDoes) {
  // a sphere of radius 2 cm in 16 x 15 facets; the tool strokes 1 mm deep along a meridian at 20 mm/s
  Surface s;
  const double big = 0.02;
  const int nu = 16, nv = 15;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double th = kPi * j / nv, ph = 2 * kPi * i / nu;
      s.n.push_back(Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
      s.v.push_back(big * s.n.back());
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = j * nu + i, b = j * nu + (i + 1) % nu, c = (j + 1) * nu + (i + 1) % nu, d = (j + 1) * nu + i;
      if (j > 0) s.t.push_back({a, d, b});
      if (j < nv - 1) s.t.push_back({b, d, c});
    }
  for (double radius : {0.0, 0.005}) {
    SCOPED_TRACE(radius > 0 ? "sphere tool" : "point tool");
    ServoParams p = test::static_surface_params(kK);
    p.tool_radius_m = radius;
    test::ServoRig<> rig(p);
    rig.dev.specs_.max_force_N = 100;
    publish(s, Vec3(0, 0, big), rig.tb.get());
    // in along the radius at 0.5 rad from the pole (0.1 s), then 0.8 s round toward the equator at 20 mm/s
    const double rt = big + radius - 0.001;
    auto at = [&](double th) { return Vec3(std::sin(th), 0.0, std::cos(th)); };
    HapticSample prev;
    double worst_move = 0.0, worst_excess_N = 0.0;
    int flips = 0, contact = 0;
    Vec3 lat_prev = Vec3::Zero();
    for (int i = 0; i < 900; ++i) {
      const double th = 0.5 + 2e-5 / rt * std::max(0, i - 100);
      rig.dev.pos_m = i < 100 ? Vec3(at(0.5) * (rt + 0.004 * (1.0 - i / 99.0))) : Vec3(at(th) * rt);
      rig.tick(i);
      const HapticSample& now = rig.servo->last_sample();
      contact += i >= 100 && now.contact == ContactState::kTouch;
      if (i > 110) {
        const double dtool = (now.tool_pos_m - prev.tool_pos_m).norm();
        // a proxy on a sphere of radius R + r turns with a device on radius R + r - 1 mm: it moves at most
        // (R + r) / (R + r - 1 mm) times as far, and its force turns by no more than the device's step explains
        worst_move = std::max(worst_move, (now.proxy_pos_m - prev.proxy_pos_m).norm() - 1.2 * dtool);
        worst_excess_N = std::max(worst_excess_N, (now.force_N - prev.force_N).norm() - kK * 1.2 * dtool);
        // the force's part across the stroke's radial direction never flips
        const Vec3 radial = now.tool_pos_m.normalized();
        const Vec3 lat = now.force_N - now.force_N.dot(radial) * radial;
        if (lat.norm() > 0.005 && lat_prev.norm() > 0.005 && lat.dot(lat_prev) < 0) ++flips;
        lat_prev = lat;
      }
      prev = now;
    }
    EXPECT_EQ(contact, 800);
    // the sphere rolls over the facets' edges within 2 um of the device's step; a point turns to the next facet's
    // normal at each convex facet edge it passes (3 on this stroke), rolling over it in bounded steps (it caught at
    // each, 0.06 N, before); neither chatters (a proxy nearest the device flips 300 times here)
    if (radius > 0) {
      EXPECT_LE(worst_move, 2e-6);
    }
    EXPECT_LE(worst_excess_N, 0.02);
    EXPECT_EQ(flips, 0);
  }
}

}  // namespace
}  // namespace palpate
