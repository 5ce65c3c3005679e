// Ray and nearest-point queries on a loaded model, checked on a box whose answers are known.
#include "runtime/session/surface_queries.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "core/scene.h"
#include "runtime/session/through_watch.h"
#include "support/obj_text.h"

namespace palpate {
namespace {

// a 100 mm box at the origin
Model box_model() {
  Scene s;
  s.mesh.box_size_m = Vec3::Constant(0.1);
  s.mesh.size_m = 0.1;
  return load_model(s).value();
}

TEST(SurfaceQueries, RayFromAboveMeetsTheTopFaceFromItsFront) {
  const Model m = box_model();
  const auto hit = first_ray_hit(m, Vec3(0.01, -0.02, 0.3), Vec3(0, 0, -2), 1.0, true);
  ASSERT_TRUE(hit);
  EXPECT_TRUE(hit->point_m.isApprox(Vec3(0.01, -0.02, 0.05), 1e-12));
  EXPECT_TRUE(hit->normal.isApprox(Vec3::UnitZ(), 1e-12));
  EXPECT_NEAR(hit->distance_m, 0.25, 1e-12);
  // too short to reach it, or pointing away: nothing
  EXPECT_FALSE(first_ray_hit(m, Vec3(0.01, -0.02, 0.3), Vec3(0, 0, -1), 0.2, true));
  EXPECT_FALSE(first_ray_hit(m, Vec3(0.01, -0.02, 0.3), Vec3(0, 0, 1), 1.0, false));
  EXPECT_FALSE(first_ray_hit(m, Vec3(0.01, -0.02, 0.3), Vec3::Zero(), 1.0, false));
}

TEST(SurfaceQueries, RayFromInsideLeavesThroughABackFaceThatOnlyAnySideCounts) {
  const Model m = box_model();
  EXPECT_FALSE(first_ray_hit(m, Vec3::Zero(), Vec3::UnitX(), 1.0, true));
  const auto hit = first_ray_hit(m, Vec3::Zero(), Vec3::UnitX(), 1.0, false);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->point_m.x(), 0.05, 1e-12);
  EXPECT_NEAR(hit->distance_m, 0.05, 1e-12);
}

TEST(SurfaceQueries, NearestPointIsExactInsideOutsideAndFarFromTheGrid) {
  const Model m = box_model();
  auto n = nearest_surface_point(m, Vec3(0.01, 0.02, 0.09));
  ASSERT_TRUE(n);
  EXPECT_TRUE(n->point_m.isApprox(Vec3(0.01, 0.02, 0.05), 1e-12));
  EXPECT_NEAR(n->distance_m, 0.04, 1e-12);
  // inside: the nearest face, 10 mm away
  n = nearest_surface_point(m, Vec3(0.0, -0.04, 0.0));
  ASSERT_TRUE(n);
  EXPECT_NEAR(n->point_m.y(), -0.05, 1e-12);
  EXPECT_NEAR(n->distance_m, 0.01, 1e-12);
  // a metre off, beyond the grid's cube
  n = nearest_surface_point(m, Vec3(1.0, 0.0, 0.0));
  ASSERT_TRUE(n);
  EXPECT_NEAR(n->distance_m, 0.95, 1e-12);
  EXPECT_TRUE(n->normal.isApprox(Vec3::UnitX(), 1e-12));
}

// depth_inside: the box's answers are its distances to the nearest face, inside; outside, or nearer the surface than
// the reach, 0; and how far the point may move with the answer unchanged
TEST(SurfaceQueries, DepthInsideIsTheDistanceToTheSurfaceOnlyInsideAndBeyondTheReach) {
  const Model m = box_model();
  ASSERT_TRUE(m.closed);
  EXPECT_NEAR(depth_inside(m, Vec3::Zero(), 0.01), 0.05, 1e-12);          // the middle, a cell no face crosses
  EXPECT_NEAR(depth_inside(m, Vec3(0.01, 0.0, 0.046), 0.001), 0.004, 1e-12);  // 4 mm under the top, in a face's cell
  EXPECT_EQ(depth_inside(m, Vec3(0.01, 0.0, 0.046), 0.005), 0.0);          // within the reach
  EXPECT_EQ(depth_inside(m, Vec3(0.01, 0.0, 0.054), 0.001), 0.0);          // 4 mm above the top
  EXPECT_EQ(depth_inside(m, Vec3(0.3, 0.0, 0.0), 0.0), 0.0);               // beyond the grid
  double still = -1.0;
  EXPECT_EQ(depth_inside(m, Vec3(0.01, 0.0, 0.049), 0.003, &still), 0.0);
  EXPECT_NEAR(still, 0.002, 1e-12);  // 1 mm under the top with a 3 mm reach: 2 mm more before it could count
  // near an edge and a corner, outside, the nearest face turns its back to the point: the rays decide, not the face
  EXPECT_EQ(depth_inside(m, Vec3(0.052, 0.0, 0.052), 0.001), 0.0);
  EXPECT_EQ(depth_inside(m, Vec3(0.052, 0.052, 0.052), 0.001), 0.0);
  EXPECT_NEAR(depth_inside(m, Vec3(0.046, 0.0, 0.047), 0.001), 0.003, 1e-12);
}

TEST(SurfaceQueries, AnOpenSurfaceHasNoInside) {
  Model m = box_model();
  // the box without its top: every edge of the opening belongs to one triangle only
  std::vector<std::array<int32_t, 3>> kept;
  for (const auto& t : m.rest.triangles) {
    bool top = true;
    for (int c = 0; c < 3; ++c) top = top && m.rest.vertices_m[static_cast<std::size_t>(t[c])].z() > 0.05 - 1e-9;
    if (!top) kept.push_back(t);
  }
  ASSERT_LT(kept.size(), m.rest.triangles.size());
  m.rest.triangles = kept;
  m.adjacency = VertexTriangles::build(m.rest.vertices_m.size(), m.rest.triangles);
  EXPECT_FALSE(closed_surface(m.rest, m.adjacency));
  m.closed = false;
  EXPECT_EQ(depth_inside(m, Vec3::Zero(), 0.01), 0.0);
}

TEST(SurfaceQueries, APathCrossesTheSurfaceOnceAtAnEdgeAndOnceWhereItStopsOnThePlane) {
  const Model m = box_model();
  std::vector<int32_t> ids;
  const Vec3 above(0.01, -0.02, 0.08), inside(0.01, -0.02, 0.0), below(0.01, -0.02, -0.08);
  EXPECT_EQ(path_crossings(m, above, inside, &ids), 1);
  EXPECT_EQ(path_crossings(m, above, below, &ids), 2);
  EXPECT_EQ(path_crossings(m, above, Vec3(0.08, -0.02, 0.08), &ids), 0);
  // stopping on the top face's plane and going on is one crossing; going back up from it, an even number (a point on
  // the plane counts as behind it)
  const Vec3 on(0.01, -0.02, 0.05);
  EXPECT_EQ(path_crossings(m, above, on, &ids) + path_crossings(m, on, inside, &ids), 1);
  EXPECT_EQ((path_crossings(m, above, on, &ids) + path_crossings(m, on, above, &ids)) % 2, 0);
  // through the corner the top face's triangles share at its centre, and through a diagonal's edge
  EXPECT_EQ(path_crossings(m, Vec3(0.0, 0.0, 0.08), Vec3(0.0, 0.0, 0.02), &ids), 1);
  int edge_hits = 0;
  for (double t = -0.045; t < 0.045; t += 0.0037) edge_hits += path_crossings(m, Vec3(t, t, 0.08), Vec3(t, t, 0.02), &ids);
  EXPECT_EQ(edge_hits, 25);
  EXPECT_EQ(path_crossings(m, above, above, &ids), 0);
}

TEST(SurfaceQueries, OnAnOpenSurfaceAPathThroughItIsCountedAndAWayRoundItIsNot) {
  // the box without its top, read from a file (an open surface: no inside); a free point's paths from inside it
  const Model box = box_model();
  TriMesh open;
  open.vertices_m = box.rest.vertices_m;
  for (const auto& t : box.rest.triangles) {
    bool top = true;
    for (int c = 0; c < 3; ++c) top = top && box.rest.vertices_m[static_cast<std::size_t>(t[c])].z() > 0.05 - 1e-9;
    if (!top) open.triangles.push_back(t);
  }
  const auto path = std::filesystem::path(testing::TempDir()) / "open_box.obj";
  std::ofstream(path) << test::obj_text(open);
  Scene scene;
  scene.mesh.file = path.string();
  scene.mesh.size_m = 0.1;
  scene.mesh.subdivisions = 0;
  scene.mode = InteractionMode::kTouch;
  const Model m = load_model(scene).value();
  ASSERT_FALSE(m.closed);
  const auto walk = [&](const std::vector<Vec3>& corners, double moved_m = 0.0) {
    FrameStats stats;
    ThroughWatch watch(scene, m, &stats);
    watch.set_moved(moved_m);
    for (std::size_t k = 0; k + 1 < corners.size(); ++k)
      for (int i = 0; i < 100; ++i) {
        HapticSample s;
        s.contact = ContactState::kFree;
        s.tool_pos_m = corners[k] + (i / 100.0) * (corners[k + 1] - corners[k]);
        s.t_s = 1e-3 * static_cast<double>(100 * k + i);
        watch.tick(s);
      }
    return stats;
  };
  const Vec3 in(0.0, 0.0, 0.0), under(0.0, 0.0, -0.09), out_above(0.0, 0.0, 0.09), beside(0.09, 0.0, 0.09);
  // down through the bottom: through, from once it is away from the bottom
  const FrameStats through = walk({in, under, under});
  EXPECT_GT(through.tool_inside_ticks, 100);
  EXPECT_EQ(through.proxy_inside_ticks, 0);
  EXPECT_GT(through.through_first_t_s, 0.0);
  // out of the opening and down the outside to the same place: never through
  EXPECT_EQ(walk({in, out_above, beside, Vec3(0.09, 0.0, -0.09), under}).tool_inside_ticks, 0);
  // a dip through the bottom and back, then away inside: never through
  EXPECT_EQ(walk({in, Vec3(0.0, 0.0, -0.0502), in, Vec3(0.02, 0.02, 0.0)}).tool_inside_ticks, 0);
  // with the material moved 2 mm (a dent's reach): a way through a wall and on into the cup is through
  EXPECT_GT(walk({Vec3(0.06, 0.003, 0.004), Vec3(0.0495, 0.003, 0.004), Vec3(0.02, 0.003, 0.004)}, 0.002).tool_inside_ticks,
            50);
}

}  // namespace
}  // namespace palpate
