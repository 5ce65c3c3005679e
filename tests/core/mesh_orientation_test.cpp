// Faces turned outward at load: inverted closed parts, patches wound against their neighbours, open shells,
// cavities and non-orientable strips.
#include "core/mesh_orientation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "core/mesh_io.h"

namespace palpate {
namespace {

using Tri = std::array<int32_t, 3>;

// the signed volume a closed mesh encloses (positive when its faces point out)
double signed_volume(const TriMesh& m) {
  double v = 0.0;
  for (const Tri& t : m.triangles)
    v += m.vertices_m[t[0]].dot(m.vertices_m[t[1]].cross(m.vertices_m[t[2]])) / 6.0;
  return v;
}

void flip(TriMesh* m, std::size_t t) { std::swap(m->triangles[t][1], m->triangles[t][2]); }

TEST(MeshOrientation, AnOutwardBoxIsLeftAsItIs) {
  TriMesh box = make_box_mesh(Vec3(0.1, 0.2, 0.3), 3);
  const TriMesh before = box;
  const MeshOrientation r = orient_outward(&box);
  EXPECT_EQ(box.triangles, before.triangles);
  EXPECT_FALSE(r.changed());
  EXPECT_EQ(r.notice(), "");
  EXPECT_EQ(r.components, 1);
  EXPECT_EQ(r.closed_components, 1);
}

TEST(MeshOrientation, ABoxWoundInwardIsTurnedInsideOut) {
  const TriMesh box = make_box_mesh(Vec3(0.1, 0.2, 0.3), 3);
  TriMesh inverted = box;
  for (std::size_t t = 0; t < inverted.triangles.size(); ++t) flip(&inverted, t);
  ASSERT_NEAR(signed_volume(inverted), -0.006, 1e-12);
  const MeshOrientation r = orient_outward(&inverted);
  EXPECT_EQ(inverted.triangles, box.triangles);  // every corner order as the outward box's
  EXPECT_NEAR(signed_volume(inverted), 0.006, 1e-12);
  EXPECT_EQ(r.triangles_flipped, 108);
  EXPECT_EQ(r.turned_inside_out, 1);
  EXPECT_EQ(r.notice(), "turned 108 of 108 triangles outward: 1 closed part wound inside out");
}

TEST(MeshOrientation, APatchWoundAgainstItsNeighboursIsTurnedBack) {
  const TriMesh box = make_box_mesh(Vec3::Constant(0.1), 4);
  for (const std::size_t patch : {std::size_t{5}, std::size_t{60}}) {
    // a patch of 5 triangles, and one of 60 (more than half of a face's 32: the volume still decides)
    TriMesh m = box;
    for (std::size_t t = 0; t < patch; ++t) flip(&m, 3 * t % m.triangles.size());
    const MeshOrientation r = orient_outward(&m);
    EXPECT_EQ(m.triangles, box.triangles) << patch;
    EXPECT_EQ(r.triangles_flipped, static_cast<int64_t>(patch));
    EXPECT_EQ(r.made_consistent, 1);
    EXPECT_EQ(r.turned_inside_out, 0);
  }
}

TEST(MeshOrientation, AnOpenShellIsOnlyMadeConsistentTheLargerAreaDeciding) {
  // the box without its top (+z) face: no inside; its winding as most of its area has it, even when inward
  TriMesh open = make_box_mesh(Vec3::Constant(0.1), 2);
  std::erase_if(open.triangles, [&](const Tri& t) {
    return open.vertices_m[t[0]].z() > 0.049 && open.vertices_m[t[1]].z() > 0.049 && open.vertices_m[t[2]].z() > 0.049;
  });
  ASSERT_EQ(open.triangles.size(), 40u);
  TriMesh inward = open;
  for (std::size_t t = 0; t < inward.triangles.size(); ++t) flip(&inward, t);
  const TriMesh inward_before = inward;
  MeshOrientation r = orient_outward(&inward);
  EXPECT_EQ(inward.triangles, inward_before.triangles);  // consistent already: a shell cannot be given an inside
  EXPECT_FALSE(r.changed());
  EXPECT_EQ(r.closed_components, 0);

  TriMesh patched = open;
  for (std::size_t t = 0; t < 6; ++t) flip(&patched, t);
  r = orient_outward(&patched);
  EXPECT_EQ(patched.triangles, open.triangles);
  EXPECT_EQ(r.triangles_flipped, 6);
}

TEST(MeshOrientation, ACavitysWallFacesIntoTheCavity) {
  // a hollow block: the outer box facing out, the inner box's faces toward the cavity (into the hole)
  const TriMesh outer = make_box_mesh(Vec3::Constant(0.1), 1);
  TriMesh inner = make_box_mesh(Vec3::Constant(0.05), 1);
  for (std::size_t t = 0; t < inner.triangles.size(); ++t) flip(&inner, t);
  TriMesh hollow = outer;
  const auto base = static_cast<int32_t>(hollow.vertices_m.size());
  hollow.vertices_m.insert(hollow.vertices_m.end(), inner.vertices_m.begin(), inner.vertices_m.end());
  for (Tri t : inner.triangles) hollow.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  TriMesh m = hollow;
  MeshOrientation r = orient_outward(&m);
  EXPECT_EQ(m.triangles, hollow.triangles);
  EXPECT_FALSE(r.changed());
  EXPECT_EQ(r.components, 2);
  EXPECT_EQ(r.cavities, 1);
  // the cavity's wall facing out of the cavity (into the material) is turned
  for (std::size_t t = outer.triangles.size(); t < m.triangles.size(); ++t) flip(&m, t);
  r = orient_outward(&m);
  EXPECT_EQ(m.triangles, hollow.triangles);
  EXPECT_EQ(r.triangles_flipped, 12);
}

TEST(MeshOrientation, AMoebiusStripIsLeftAsRead) {
  // 12 quads round a ring, the band turning half a turn: no winding agrees across all edges
  TriMesh m;
  const int n = 12;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n, h = 0.5 * a;
    const Vec3 centre(std::cos(a), std::sin(a), 0.0);
    const Vec3 across = std::cos(h) * centre + std::sin(h) * Vec3::UnitZ();
    m.vertices_m.push_back(centre + 0.2 * across);
    m.vertices_m.push_back(centre - 0.2 * across);
  }
  for (int i = 0; i < n; ++i) {
    const int32_t a = 2 * i, b = 2 * i + 1;
    // the last quad meets the first band with its sides swapped
    const int32_t c = i + 1 < n ? 2 * (i + 1) : 1, d = i + 1 < n ? 2 * (i + 1) + 1 : 0;
    m.triangles.push_back({a, b, d});
    m.triangles.push_back({a, d, c});
  }
  const TriMesh before = m;
  const MeshOrientation r = orient_outward(&m);
  EXPECT_EQ(m.triangles, before.triangles);
  EXPECT_EQ(r.not_orientable, 1);
  EXPECT_EQ(r.notice(), "1 part left as read (no winding agrees across all its edges)");
}

}  // namespace
}  // namespace palpate
