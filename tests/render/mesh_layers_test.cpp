// The static/dynamic split: moving vertices, the triangles whose shading they change, the edges they move, and
// the dynamic part's own compact vertex array.
#include "render/mesh_layers.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace palpate {

namespace {

// A strip of 6 triangles over vertices 0..7 (two rows of four): 0-1-2-3 on top, 4-5-6-7 below.
const std::vector<std::array<int32_t, 3>> kStrip = {{0, 4, 1}, {1, 4, 5}, {1, 5, 2}, {2, 5, 6}, {2, 6, 3}, {3, 6, 7}};

// Local indices mapped back to mesh vertices.
std::vector<uint32_t> to_mesh(const MeshLayers& layers, const std::vector<uint32_t>& local) {
  std::vector<uint32_t> out;
  for (uint32_t i : local) out.push_back(static_cast<uint32_t>(layers.local_vertices().at(i)));
  return out;
}

// The local array: the affected vertices first, each used vertex once, nothing unused.
void expect_compact(const MeshLayers& layers) {
  const auto& local = layers.local_vertices();
  const auto& affected = layers.affected_vertices();
  ASSERT_GE(local.size(), affected.size());
  EXPECT_TRUE(std::equal(affected.begin(), affected.end(), local.begin()));
  auto sorted = local;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "a vertex listed twice";
  std::vector<bool> used(local.size(), false);
  for (uint32_t i : layers.dynamic_triangles()) used.at(i) = true;
  for (uint32_t i : layers.dynamic_edges()) used.at(i) = true;
  for (std::size_t i = affected.size(); i < local.size(); ++i) EXPECT_TRUE(used[i]) << "local vertex " << i;
}

TEST(MeshLayers, OneMovingCornerMakesItsTrianglesAndTheirNeighboursDynamic) {
  const std::vector<uint32_t> edges = {0, 1, 1, 2, 2, 3, 4, 5, 5, 6, 6, 7, 0, 4, 1, 4, 1, 5, 2, 5, 2, 6, 3, 6, 3, 7};
  MeshLayers layers;
  layers.split(8, kStrip, edges, {0});
  // vertex 0 moves: triangle 0 changes shape, so normals of 0, 4, 1 change; every triangle touching 0, 1 or 4
  // is dynamic (0, 1, 2); the rest keep their shading
  EXPECT_EQ(layers.affected_vertices(), (std::vector<int32_t>{0, 1, 4}));
  EXPECT_EQ(to_mesh(layers, layers.dynamic_triangles()), (std::vector<uint32_t>{0, 4, 1, 1, 4, 5, 1, 5, 2}));
  EXPECT_EQ(layers.static_triangles(), (std::vector<uint32_t>{2, 5, 6, 2, 6, 3, 3, 6, 7}));
  // lines are unlit: only the edges at vertex 0 move
  EXPECT_EQ(to_mesh(layers, layers.dynamic_edges()), (std::vector<uint32_t>{0, 1, 0, 4}));
  EXPECT_EQ(layers.static_edges().size() + layers.dynamic_edges().size(), edges.size());
  // the dynamic part draws from 5 of the 8 vertices: the affected ones, then 5 and 2 in the order first used
  EXPECT_EQ(layers.local_vertices(), (std::vector<int32_t>{0, 1, 4, 5, 2}));
  EXPECT_EQ(layers.dynamic_triangles(), (std::vector<uint32_t>{0, 2, 1, 1, 2, 3, 1, 3, 4}));
  expect_compact(layers);
}

TEST(MeshLayers, NothingMovingLeavesEverythingStaticAndResplitsCleanly) {
  MeshLayers layers;
  layers.split(8, kStrip, {}, {7});
  EXPECT_EQ(to_mesh(layers, layers.dynamic_triangles()), (std::vector<uint32_t>{2, 5, 6, 2, 6, 3, 3, 6, 7}));
  EXPECT_EQ(layers.local_vertices(), (std::vector<int32_t>{3, 6, 7, 2, 5}));
  expect_compact(layers);
  layers.split(8, kStrip, {}, {});
  EXPECT_TRUE(layers.dynamic_triangles().empty());
  EXPECT_TRUE(layers.affected_vertices().empty());
  EXPECT_TRUE(layers.local_vertices().empty());
  EXPECT_EQ(layers.static_triangles().size(), 3 * kStrip.size());
}

// A cut inside the dynamic part: triangle 0 (all of its corners affected) is split through two new moving vertices.
TEST(MeshLayers, GrowingInsideTheDynamicPartGivesTheSplitOfTheGrownMesh) {
  MeshLayers grown;
  grown.split(8, kStrip, {}, {0});
  auto cut = kStrip;
  cut[0] = {0, 8, 1};
  cut.push_back({8, 4, 9});
  cut.push_back({9, 4, 1});
  const std::vector<int32_t> moving = {0, 8, 9};
  ASSERT_TRUE(grown.grow(10, cut, moving));
  MeshLayers whole;
  whole.split(10, cut, {}, moving);
  EXPECT_EQ(grown.affected_vertices(), whole.affected_vertices());
  EXPECT_EQ(grown.local_vertices(), whole.local_vertices());
  EXPECT_EQ(grown.dynamic_triangles(), whole.dynamic_triangles());
  EXPECT_EQ(grown.static_triangles(), whole.static_triangles());
  EXPECT_EQ(to_mesh(grown, grown.dynamic_triangles()),
            (std::vector<uint32_t>{0, 8, 1, 1, 4, 5, 1, 5, 2, 8, 4, 9, 9, 4, 1}));
  expect_compact(grown);
}

TEST(MeshLayers, GrowingRefusesWhatWouldChangeTheStaticPart) {
  auto refused = [](const std::vector<std::array<int32_t, 3>>& tris, std::size_t n_v, const std::vector<int32_t>& moving,
                    const std::vector<uint32_t>& edges) {
    MeshLayers layers;
    layers.split(8, kStrip, edges, {0});
    const auto before = layers.dynamic_triangles();
    const bool grew = layers.grow(n_v, tris, moving);
    if (!grew) {
      EXPECT_EQ(layers.dynamic_triangles(), before);  // nothing changed
    }
    return !grew;
  };
  auto at_static = kStrip;
  at_static.push_back({8, 5, 6});  // vertices 5 and 6 are static: their triangles would turn dynamic
  EXPECT_TRUE(refused(at_static, 9, {0, 8}, {}));
  auto grown = kStrip;
  grown.push_back({8, 4, 1});
  EXPECT_TRUE(refused(grown, 9, {0}, {}));         // a new vertex that does not move
  EXPECT_TRUE(refused(grown, 9, {0, 7, 8}, {}));   // a static vertex that now moves
  EXPECT_TRUE(refused(grown, 9, {0, 8}, {0, 1}));  // the lines would change too
  EXPECT_FALSE(refused(grown, 9, {0, 8}, {}));
}

}  // namespace
}  // namespace palpate
