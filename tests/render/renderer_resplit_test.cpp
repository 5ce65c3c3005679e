// The layered path keeps its layer while the triangles change only where vertices move (a cut inside the moving
// part, FrameView::static_part_kept), and every frame still has the pixels of a full redraw.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "core/aabb.h"
#include "core/mesh_io.h"
#include "core/tri_mesh.h"
#include "render/gl_context_factory.h"
#include "render/renderer.h"
#include "render_test_util.h"

namespace palpate {
namespace {

using test::count_different;

constexpr int kW = 160;
constexpr int kH = 120;

// The moving vertices pressed `amount` steps in from rest: further toward +x and -y.
void press(const std::vector<Vec3>& rest, const std::vector<int32_t>& moving, double amount, TriMesh* m) {
  for (int32_t v : moving) {
    const Vec3& r = rest[static_cast<std::size_t>(v)];
    m->vertices_m[static_cast<std::size_t>(v)] = r + amount * Vec3(-0.003 * (r.x() - 0.02) * 20, 0.001, -0.002 * (1 + r.y() * 10));
  }
}

// A view of m, its normals and moving vertices, at layer epoch `epoch`.
FrameView moving_view(const TriMesh& m, const std::vector<Vec3>& normals, const std::vector<int32_t>& moving, uint64_t epoch) {
  FrameView view{};
  view.vertices_m = &m.vertices_m;
  view.triangles = &m.triangles;
  view.normals = &normals;
  view.moving_vertices = &moving;
  view.layer_epoch = epoch;
  return view;
}

// The frame drawn layered into *a (checked to be layered) and by a full redraw into *b.
void draw_both(Renderer* layered, Renderer* full, const FrameView& view, std::vector<uint8_t>* a,
               std::vector<uint8_t>* b) {
  layered->draw(view, a->data());
  EXPECT_TRUE(layered->last_draw_layered());
  full->draw(view, b->data());
}

class RendererResplitTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    auto ctx = create_gl_context(kW, kH, from_name<RenderBackend>(GetParam()).value());
    if (!ctx.ok()) {
      const std::string& m = ctx.error().message;
      if (GetParam() == "egl" && m.find("not available") != std::string::npos) GTEST_SKIP() << m;
      FAIL() << m;
    }
    ctx_ = std::move(ctx.value());
  }
  std::unique_ptr<GlContext> ctx_;
};

// A box whose +x part moves; each frame one moving triangle is split at its centroid into three (a new vertex,
// moving, appended: the triangle count and vertex count grow) and the moving part is pressed in further. The layer
// is drawn once; the dynamic part is split again every frame; the pixels are a full redraw's.
TEST_P(RendererResplitTest, ATopologyChangeInsideTheMovingPartKeepsTheLayerAndTheFullRedrawsPixels) {
  TriMesh mesh = ::palpate::make_box_mesh(Vec3(0.1, 0.08, 0.06), 8);
  const Aabb box = Aabb::of(mesh.vertices_m);
  const Camera cam = Camera::framing(box.min_m, box.max_m, static_cast<double>(kW) / kH);
  for (RenderStyle style : {RenderStyle::kBoth, RenderStyle::kSolid}) {
    TriMesh m = mesh;
    std::vector<Vec3> rest = m.vertices_m;
    Renderer layered(ctx_.get(), style, cam), full(ctx_.get(), style, cam);
    full.set_layered(false);
    std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size()), first(a.size());
    std::vector<int32_t> moving;
    for (std::size_t v = 0; v < rest.size(); ++v)
      if (rest[v].x() > 0.02) moving.push_back(static_cast<int32_t>(v));
    std::vector<Vec3> normals;
    uint64_t topology = 0;
    for (int f = 0; f < 6; ++f) {
      if (f > 0) {
        // split the first triangle whose corners all move at its centroid
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
          const auto tri = m.triangles[t];
          auto moves = [&](int32_t v) { return std::binary_search(moving.begin(), moving.end(), v); };
          if (!moves(tri[0]) || !moves(tri[1]) || !moves(tri[2])) continue;
          const auto c = static_cast<int32_t>(rest.size());
          rest.push_back((rest[tri[0]] + rest[tri[1]] + rest[tri[2]]) / 3.0);
          m.vertices_m.push_back(rest.back());
          moving.push_back(c);
          m.triangles[t] = {tri[0], tri[1], c};
          m.triangles.push_back({tri[1], tri[2], c});
          m.triangles.push_back({tri[2], tri[0], c});
          ++topology;
          break;
        }
      }
      press(rest, moving, f, &m);
      compute_vertex_normals(m.vertices_m, m.triangles, &normals);
      FrameView view = moving_view(m, normals, moving, 7);
      view.topology_epoch = topology;
      view.static_part_kept = true;
      draw_both(&layered, &full, view, &a, &b);
      EXPECT_EQ(count_different(a, b), 0) << "style " << static_cast<int>(style) << " frame " << f;
      if (f == 0) first = a;
    }
    EXPECT_EQ(layered.layer_builds(), 1);
    EXPECT_EQ(layered.resplits(), 5);
    EXPECT_GT(count_different(first, a), 100);  // the frames differ: the comparison is not of still images
  }
}

// The moving set shrinks to a part of itself (the +x, +y corner) while the rest of the mesh stays where the layer drew
// it: the new layer is redrawn only in the rectangle the old moving part covered, and every frame, before and after,
// has the pixels of a full redraw.
TEST_P(RendererResplitTest, ANewMovingSetRedrawsOnlyTheRectangleThatChangedAndTheFullRedrawsPixels) {
  TriMesh m = ::palpate::make_box_mesh(Vec3(0.1, 0.08, 0.06), 10);
  const std::vector<Vec3> rest = m.vertices_m;
  const Aabb box = Aabb::of(rest);
  const Camera cam = Camera::framing(box.min_m, box.max_m, static_cast<double>(kW) / kH);
  Renderer layered(ctx_.get(), RenderStyle::kSolid, cam), full(ctx_.get(), RenderStyle::kSolid, cam);
  full.set_layered(false);
  std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size()), first(a.size());
  std::vector<int32_t> moving;
  std::vector<Vec3> normals;
  int64_t parts = 0;
  for (int f = 0; f < 8; ++f) {
    const int epoch = f < 4 ? 0 : 1;
    moving.clear();
    for (std::size_t v = 0; v < rest.size(); ++v)
      if (rest[v].x() > 0.02 && (epoch == 0 || rest[v].y() > 0.0)) moving.push_back(static_cast<int32_t>(v));
    // the moving part pressed in further each frame, but not on the frame its set changes
    if (f != 4) press(rest, moving, f + 1, &m);
    compute_vertex_normals(m.vertices_m, m.triangles, &normals);
    const FrameView view = moving_view(m, normals, moving, static_cast<uint64_t>(epoch));
    const int64_t builds = layered.layer_builds();
    layered.draw(view, a.data());
    EXPECT_TRUE(layered.last_draw_layered());
    if (layered.layer_builds() != builds && layered.last_layer_px() < int64_t{kW} * kH) ++parts;
    full.draw(view, b.data());
    EXPECT_EQ(count_different(a, b), 0) << "frame " << f;
    if (f == 0) first = a;
  }
  EXPECT_EQ(layered.layer_builds(), 2);
  EXPECT_EQ(parts, 1);  // the second layer, in part
  EXPECT_GT(layered.last_layer_px(), 0);
  EXPECT_GT(count_different(first, a), 100);  // the frames differ: the comparison is not of still images
  // drawn whole, the same frames come out alike
  Renderer whole(ctx_.get(), RenderStyle::kSolid, cam);
  whole.set_layer_patching(false);
  FrameView view{};
  view.vertices_m = &m.vertices_m;
  view.triangles = &m.triangles;
  view.normals = &normals;
  view.moving_vertices = &moving;
  whole.draw(view, b.data());
  EXPECT_EQ(whole.last_layer_px(), int64_t{kW} * kH);
  EXPECT_EQ(count_different(a, b), 0);
}

// A moving part that holds still while the tool and blade move over it (a cut between splits): the dynamic part is
// drawn on the frame it changes and the one after, whose image the still frames copy; every frame has the pixels of
// a full redraw, the frame it moves again too.
TEST_P(RendererResplitTest, AStillMovingPartIsDrawnOnlyWhenItChangesAndTheFullRedrawsPixels) {
  TriMesh m = ::palpate::make_box_mesh(Vec3(0.1, 0.08, 0.06), 8);
  const std::vector<Vec3> rest = m.vertices_m;
  const Aabb box = Aabb::of(rest);
  const Camera cam = Camera::framing(box.min_m, box.max_m, static_cast<double>(kW) / kH);
  for (RenderStyle style : {RenderStyle::kBoth, RenderStyle::kSolid}) {
    Renderer layered(ctx_.get(), style, cam), full(ctx_.get(), style, cam);
    full.set_layered(false);
    std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size()), first(a.size());
    std::vector<int32_t> moving;
    for (std::size_t v = 0; v < rest.size(); ++v)
      if (rest[v].x() > 0.02) moving.push_back(static_cast<int32_t>(v));
    std::vector<Vec3> normals;
    for (int f = 0; f < 10; ++f) {
      // pressed in on frames 0 and 6 only
      if (f == 0 || f == 6) press(rest, moving, f + 1, &m);
      compute_vertex_normals(m.vertices_m, m.triangles, &normals);
      FrameView view = moving_view(m, normals, moving, 3);
      view.show_blade = true;
      view.blade_tip_m = Vec3(0.04, -0.02 + 0.004 * f, 0.07);
      view.blade_end_m = view.blade_tip_m + Vec3(0.0, 0.0, 0.03);
      view.tool_pos_m = view.blade_tip_m;
      view.tool_radius_m = 0.004;
      draw_both(&layered, &full, view, &a, &b);
      EXPECT_EQ(count_different(a, b), 0) << "style " << static_cast<int>(style) << " frame " << f;
      if (f == 0) first = a;
    }
    EXPECT_EQ(layered.layer_builds(), 1);
    // frames 0, 1, 6 and 7 drew it: of the ten, the six still frames after those copied its image
    EXPECT_EQ(layered.dynamic_draws(), 4);
    EXPECT_GT(count_different(first, a), 100);  // the mesh moved and the tool with the blade: not still images
  }
}

INSTANTIATE_TEST_SUITE_P(Backends, RendererResplitTest, ::testing::Values("osmesa", "egl"),
                         [](const auto& param_info) { return param_info.param; });

}  // namespace
}  // namespace palpate
