// The static/dynamic split: moving vertices, the triangles whose shading they change, the edges they move.
#include "render/mesh_layers.h"

#include <gtest/gtest.h>

namespace palpate {
namespace {

// A strip of 6 triangles over vertices 0..7 (two rows of four): 0-1-2-3 on top, 4-5-6-7 below.
const std::vector<std::array<int32_t, 3>> kStrip = {{0, 4, 1}, {1, 4, 5}, {1, 5, 2}, {2, 5, 6}, {2, 6, 3}, {3, 6, 7}};

TEST(MeshLayers, OneMovingCornerMakesItsTrianglesAndTheirNeighboursDynamic) {
  const std::vector<uint32_t> edges = {0, 1, 1, 2, 2, 3, 4, 5, 5, 6, 6, 7, 0, 4, 1, 4, 1, 5, 2, 5, 2, 6, 3, 6, 3, 7};
  MeshLayers layers;
  layers.split(8, kStrip, edges, {0});
  // vertex 0 moves: triangle 0 changes shape, so normals of 0, 4, 1 change; every triangle touching 0, 1 or 4
  // is dynamic (0, 1, 2); the rest keep their shading
  EXPECT_EQ(layers.affected_vertices(), (std::vector<int32_t>{0, 1, 4}));
  EXPECT_EQ(layers.dynamic_triangles(), (std::vector<uint32_t>{0, 4, 1, 1, 4, 5, 1, 5, 2}));
  EXPECT_EQ(layers.static_triangles(), (std::vector<uint32_t>{2, 5, 6, 2, 6, 3, 3, 6, 7}));
  // lines are unlit: only the edges at vertex 0 move
  EXPECT_EQ(layers.dynamic_edges(), (std::vector<uint32_t>{0, 1, 0, 4}));
  EXPECT_EQ(layers.static_edges().size() + layers.dynamic_edges().size(), edges.size());
}

TEST(MeshLayers, NothingMovingLeavesEverythingStaticAndResplitsCleanly) {
  MeshLayers layers;
  layers.split(8, kStrip, {}, {7});
  EXPECT_EQ(layers.dynamic_triangles(), (std::vector<uint32_t>{2, 5, 6, 2, 6, 3, 3, 6, 7}));
  layers.split(8, kStrip, {}, {});
  EXPECT_TRUE(layers.dynamic_triangles().empty());
  EXPECT_TRUE(layers.affected_vertices().empty());
  EXPECT_EQ(layers.static_triangles().size(), 3 * kStrip.size());
}

}  // namespace
}  // namespace palpate
