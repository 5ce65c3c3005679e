#include "render/mesh_lod.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "core/aabb.h"
#include "core/mesh_io.h"
#include "render/gl_context_factory.h"
#include "core/tri_mesh.h"
#include "render/renderer.h"
#include "render_test_util.h"

namespace palpate {
namespace {

constexpr int kW = 160;
constexpr int kH = 120;

// a sphere of radius 5 cm, 110 592 triangles: at 160 x 120 its median edge is about a third of a pixel
TriMesh dense_sphere() {
  TriMesh mesh = subdivide_midpoint(subdivide_midpoint(make_box_mesh(Vec3(0.1, 0.1, 0.1), 24)));
  const Vec3 c = Aabb::of(mesh.vertices_m).center();
  for (Vec3& v : mesh.vertices_m) v = c + 0.05 * (v - c).normalized();
  return mesh;
}

bool background(const std::vector<uint8_t>& rgba, int x, int y) {
  const auto p = test::pixel(rgba, kW, x, y);
  return std::abs(p[0] - 247) <= 2 && std::abs(p[1] - 247) <= 2 && std::abs(p[2] - 250) <= 2;
}

class MeshLodTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto ctx = create_gl_context(kW, kH, RenderBackend::kAuto);
    ASSERT_TRUE(ctx.ok()) << ctx.error().message;
    ctx_ = std::move(ctx.value());
    const Aabb box = Aabb::of(sphere_.vertices_m);
    camera_ = Camera::framing(box.min_m, box.max_m, static_cast<double>(kW) / kH);
    renderer_ = std::make_unique<Renderer>(ctx_.get(), RenderStyle::kSolid, camera_);
    project_ = [this](const Vec3& p) { return renderer_->project(p); };
  }
  TriMesh sphere_ = dense_sphere();
  std::unique_ptr<GlContext> ctx_;
  Camera camera_;
  std::unique_ptr<Renderer> renderer_;
  ProjectFn project_;
};

TEST_F(MeshLodTest, LeavesAMeshAsCoarseAsTheImageAlone) {
  const TriMesh box = test::make_box_mesh(Vec3(-0.05, -0.05, -0.05), Vec3(0.05, 0.05, 0.05));
  EXPECT_FALSE(screen_lod(box.vertices_m, box.triangles, project_, 1.0).has_value());
  EXPECT_FALSE(screen_lod(sphere_.vertices_m, sphere_.triangles, project_, 0.0).has_value());  // 0: never
  EXPECT_FALSE(screen_lod(sphere_.vertices_m, {}, project_, 1.0).has_value());
  EXPECT_TRUE(screen_lod(sphere_.vertices_m, sphere_.triangles, project_, 1.0).has_value());
}

// The clustered sphere: its median edge reaches the target, it keeps a fraction of the triangles, every vertex
// lies within a cell's diagonal of the one that stands for it, and it indexes only the input's vertices.
TEST_F(MeshLodTest, ClustersToAboutAPixelWithinACellOfTheSurface) {
  const double before = median_edge_px(sphere_.vertices_m, sphere_.triangles, project_);
  EXPECT_LT(before, 0.5);
  const auto lod = screen_lod(sphere_.vertices_m, sphere_.triangles, project_, 1.0);
  ASSERT_TRUE(lod.has_value());
  EXPECT_DOUBLE_EQ(lod->median_edge_px, before);
  EXPECT_GE(lod->lod_median_edge_px, 0.95);
  EXPECT_LT(lod->lod_median_edge_px, 2.0);
  EXPECT_DOUBLE_EQ(lod->lod_median_edge_px, median_edge_px(sphere_.vertices_m, lod->triangles, project_));
  EXPECT_LT(lod->triangles.size(), sphere_.triangles.size() / 4);
  EXPECT_GT(lod->triangles.size(), 5000u);
  EXPECT_GT(lod->max_shift_m, 0.0);
  EXPECT_LE(lod->max_shift_m, std::sqrt(3.0) * lod->cell_m);
  EXPECT_LT(lod->max_shift_px, 3.0);
  std::vector<uint8_t> used(sphere_.vertices_m.size(), 0);
  std::size_t distinct = 0;
  for (const auto& t : lod->triangles) {
    EXPECT_TRUE(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
    for (int32_t i : t) {
      ASSERT_GE(i, 0);
      ASSERT_LT(static_cast<std::size_t>(i), used.size());
      distinct += used[i] == 0 ? 1 : 0;
      used[i] = 1;
    }
  }
  EXPECT_EQ(distinct, lod->representatives);
  // the same input gives the same triangles
  EXPECT_EQ(screen_lod(sphere_.vertices_m, sphere_.triangles, project_, 1.0)->triangles, lod->triangles);
}

// Drawn with the input's own normals, the clustered sphere gives the full mesh's image up to its bound: pixels
// change from background to surface or back only within the shift of the full image's outline, and inside the
// surface the shading is the same to a few levels.
TEST_F(MeshLodTest, ImageDiffersOnlyAtTheOutlineWithinTheShiftAndByAFewLevelsInside) {
  const auto lod = screen_lod(sphere_.vertices_m, sphere_.triangles, project_, 1.0);
  ASSERT_TRUE(lod.has_value());
  std::vector<Vec3> normals;
  const Vec3 c = Aabb::of(sphere_.vertices_m).center();
  for (const Vec3& v : sphere_.vertices_m) normals.push_back((v - c).normalized());
  FrameView view{};
  view.vertices_m = &sphere_.vertices_m;
  view.normals = &normals;
  std::vector<uint8_t> full(static_cast<std::size_t>(kW) * kH * 4), coarse(full.size());
  view.triangles = &sphere_.triangles;
  Renderer(ctx_.get(), RenderStyle::kSolid, camera_).draw(view, full.data());
  view.triangles = &lod->triangles;
  Renderer(ctx_.get(), RenderStyle::kSolid, camera_).draw(view, coarse.data());

  const int reach = static_cast<int>(std::ceil(lod->max_shift_px)) + 1;
  auto near_outline = [&](int x, int y) {
    for (int v = std::max(0, y - reach); v <= std::min(kH - 1, y + reach); ++v)
      for (int u = std::max(0, x - reach); u <= std::min(kW - 1, x + reach); ++u) {
        const bool b = background(full, u, v);
        if ((u + 1 < kW && background(full, u + 1, v) != b) || (v + 1 < kH && background(full, u, v + 1) != b))
          return true;
      }
    return false;
  };
  int outline_changed = 0, inside = 0, far_off = 0;
  double sum = 0.0;
  int worst = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool bf = background(full, x, y), bc = background(coarse, x, y);
      if (bf != bc) {
        ++outline_changed;
        far_off += near_outline(x, y) ? 0 : 1;
        continue;
      }
      if (bf) continue;
      const auto p = test::pixel(full, kW, x, y), q = test::pixel(coarse, kW, x, y);
      for (int k = 0; k < 3; ++k) {
        sum += std::abs(p[k] - q[k]);
        worst = std::max(worst, std::abs(p[k] - q[k]));
      }
      ++inside;
    }
  EXPECT_GT(inside, 3000);
  EXPECT_EQ(far_off, 0);
  EXPECT_LT(outline_changed, inside / 20);
  const double mean = sum / (3.0 * inside);
  // a fold-over facing away from its source would be lit as a back face: 120 levels darker
  EXPECT_LT(mean, 0.5) << "worst " << worst;
  EXPECT_LE(worst, 8);
  std::printf("outline changed %d of %d; mean %.3f worst %d levels; max shift %.2f px; %zu -> %zu triangles\n",
              outline_changed, inside, mean, worst, lod->max_shift_px, sphere_.triangles.size(), lod->triangles.size());
}

}  // namespace
}  // namespace palpate
