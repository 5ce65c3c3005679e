// What a frame says besides the model's shape, read from real pixels of a real GL context: the surface coloured by
// displacement with the map's top at the most displaced vertex and the legend beside it, the same pixels whether
// the frame is drawn whole or from its cached layer, the force arrow's length in proportion to the force, the faces a
// cut made in their own colour (the legend's numbers and the trace's inset: annotate_text_test.cpp).
#include "render/annotate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "render/gl_context_factory.h"
#include "render/renderer.h"
#include "render_test_util.h"

namespace palpate {
namespace {

using test::pixel;

constexpr int kW = 320;
constexpr int kH = 240;

// A 40 x 40 sheet of quads over 6 cm x 6 cm, its normals up.
TriMesh sheet() {
  TriMesh m;
  const int n = 40;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices_m.emplace_back(0.06 * i / n - 0.03, 0.06 * j / n - 0.03, 0.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
      m.triangles.push_back({a, b, c});
      m.triangles.push_back({a, c, d});
    }
  return m;
}

// A redness of a lit pixel: how much red exceeds blue (the map runs from blue-grey to red).
int redness(const std::array<int, 4>& p) { return p[0] - p[2]; }

class AnnotateRender : public ::testing::Test {
 protected:
  void SetUp() override {
    auto ctx = create_gl_context(kW, kH, RenderBackend::kOsmesa);
    ASSERT_TRUE(ctx.ok()) << ctx.error().message;
    ctx_ = std::move(ctx.value());
    rest_ = sheet();
    camera_ = Camera::framing(Vec3(-0.03, -0.03, -0.01), Vec3(0.03, 0.03, 0.02), static_cast<double>(kW) / kH);
  }

  // the sheet pushed up by a bump of height h (a Gaussian of 8 mm around `at`, x and y); the vertices it moves
  std::vector<Vec3> bumped(double h, std::vector<int32_t>* moving = nullptr, const Vec3& at = Vec3::Zero()) const {
    std::vector<Vec3> v = rest_.vertices_m;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const double r2 = (v[i] - at).head<2>().squaredNorm();
      if (r2 < 0.015 * 0.015) {
        v[i].z() += h * std::exp(-r2 / (2 * 0.008 * 0.008));
        if (moving) moving->push_back(static_cast<int32_t>(i));
      }
    }
    return v;
  }

  // the sheet at v, coloured up to 1 cm, `moving` free to move within layer `epoch`
  FrameView coloured(const std::vector<Vec3>& v, const std::vector<int32_t>* moving, uint64_t epoch) const {
    FrameView view;
    view.vertices_m = &v;
    view.triangles = &rest_.triangles;
    view.rest_m = &rest_.vertices_m;
    view.color_range_m = 0.01;
    view.moving_vertices = moving;
    view.layer_epoch = epoch;
    return view;
  }

  std::unique_ptr<GlContext> ctx_;
  TriMesh rest_;
  Camera camera_;
};

TEST_F(AnnotateRender, TheMapsTopIsAtTheMostDisplacedVertexAndTheLegendSaysSo) {
  const double h = 0.008;
  const std::vector<Vec3> v = bumped(h);
  FrameView view;
  view.vertices_m = &v;
  view.triangles = &rest_.triangles;
  view.rest_m = &rest_.vertices_m;
  view.color_range_m = h;
  view.show_legend = true;
  Renderer renderer(ctx_.get(), RenderStyle::kSolid, camera_);
  std::vector<uint8_t> rgba(static_cast<std::size_t>(kW) * kH * 4);
  renderer.draw(view, rgba.data());
  // the apex (displaced by the whole range) is red, a corner of the sheet (not moved) the model's blue-grey
  const Eigen::Vector2d apex = renderer.project(v[20 * 41 + 20]);
  const Eigen::Vector2d corner = renderer.project(v[2 * 41 + 2]);
  const auto top = pixel(rgba, kW, static_cast<int>(apex.x()), static_cast<int>(apex.y()) + 1);
  const auto flat = pixel(rgba, kW, static_cast<int>(corner.x()), static_cast<int>(corner.y()));
  EXPECT_GT(redness(top), 60) << top[0] << " " << top[1] << " " << top[2];
  EXPECT_LT(redness(flat), 0) << flat[0] << " " << flat[1] << " " << flat[2];
  // the legend's bar holds the map's top colour exactly (drawn into the image, unlit), in the top-right corner
  int top_color_px = 0, x_min = kW;
  for (int y = 0; y < kH / 2; ++y)
    for (int x = 0; x < kW; ++x) {
      const auto p = pixel(rgba, kW, x, y);
      if (p[0] == 176 && p[1] == 26 && p[2] == 30) ++top_color_px, x_min = std::min(x_min, x);
    }
  EXPECT_GT(top_color_px, 0);
  EXPECT_GT(x_min, kW / 2);
  // without a range the same surface is one colour: the apex no redder than the flat sheet's blue-grey allows
  view.color_range_m = 0.0;
  view.show_legend = false;
  Renderer plain(ctx_.get(), RenderStyle::kSolid, camera_);
  plain.draw(view, rgba.data());
  EXPECT_LT(redness(pixel(rgba, kW, static_cast<int>(apex.x()), static_cast<int>(apex.y()) + 1)), 0);
}

TEST_F(AnnotateRender, ColouredFramesFromTheCachedLayerAreTheFullRedrawsPixelForPixel) {
  std::vector<int32_t> moving;
  bumped(0.0, &moving);
  Renderer layered(ctx_.get(), RenderStyle::kSolid, camera_), whole(ctx_.get(), RenderStyle::kSolid, camera_);
  whole.set_layered(false);
  std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size());
  // the bump grows over frames; the layer is drawn once and the moving part's colours follow
  for (double h : {0.0, 0.002, 0.005, 0.008}) {
    const std::vector<Vec3> v = bumped(h);
    const FrameView view = coloured(v, &moving, 1);
    layered.draw(view, a.data());
    whole.draw(view, b.data());
    EXPECT_EQ(test::count_different(a, b), 0) << "bump " << h;
  }
  EXPECT_EQ(layered.layer_builds(), 1);
}

// The floor under a sheet held 1 cm above it, with the sheet's shadow: a bump rising in one place, then in another
// (a new moving set: the layer is redrawn only in the rectangle where the parts and their shadows changed), drawn
// from the cached layer and in full, pixel for pixel the same; the shadow is on the floor.
TEST_F(AnnotateRender, TheFloorAndTheShadowsFromTheLayerAreTheFullRedrawsPixelForPixel) {
  for (Vec3& p : rest_.vertices_m) p.z() = 0.01;
  camera_ = Camera::framing(Vec3(-0.04, -0.04, 0.0), Vec3(0.04, 0.04, 0.03), static_cast<double>(kW) / kH);
  Renderer layered(ctx_.get(), RenderStyle::kSolid, camera_), whole(ctx_.get(), RenderStyle::kSolid, camera_);
  whole.set_layered(false);
  std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size());
  int shadow_px = 0;
  for (const Vec3& at : {Vec3(0.0, 0.0, 0.0), Vec3(0.012, 0.006, 0.0)}) {
    std::vector<int32_t> moving;
    bumped(0.0, &moving, at);
    for (double h : {0.0, 0.004, 0.008}) {
      const std::vector<Vec3> v = bumped(h, nullptr, at);
      FrameView view = coloured(v, &moving, at.x() > 0.0 ? 2 : 1);
      view.floor_z_m = 0.0;
      view.floor_half_m = 0.06;
      layered.draw(view, a.data());
      whole.draw(view, b.data());
      EXPECT_EQ(test::count_different(a, b), 0) << "bump " << h << " at " << at.x();
    }
  }
  EXPECT_EQ(layered.layer_builds(), 2);
  // the second layer was redrawn in part
  EXPECT_LT(layered.last_layer_px(), int64_t{kW} * kH);
  // a closed surface's shadow is drawn from the faces toward the light alone: the same triangles on both paths
  {
    Renderer l2(ctx_.get(), RenderStyle::kSolid, camera_), w2(ctx_.get(), RenderStyle::kSolid, camera_);
    w2.set_layered(false);
    std::vector<int32_t> moving;
    bumped(0.0, &moving);
    const std::vector<Vec3> v = bumped(0.006);
    FrameView view;
    view.vertices_m = &v;
    view.triangles = &rest_.triangles;
    view.moving_vertices = &moving;
    view.layer_epoch = 1;
    view.floor_z_m = 0.0;
    view.floor_half_m = 0.06;
    view.closed_surface = true;
    std::vector<uint8_t> c(a.size()), d(a.size());
    l2.draw(view, c.data());
    w2.draw(view, d.data());
    EXPECT_EQ(test::count_different(c, d), 0);
  }
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const auto p = pixel(a, kW, x, y);
      shadow_px += std::abs(p[0] - 168) <= 2 && std::abs(p[1] - 171) <= 2 && std::abs(p[2] - 181) <= 2 ? 1 : 0;
    }
  EXPECT_GT(shadow_px, 200);
}

// Multisampled frames: the flat sheet's silhouette (one lit colour on the background) has pixels between the two,
// where one sample a pixel has none; the cached layer's frames equal the full redraw's multisampled too.
TEST_F(AnnotateRender, MultisampledFramesSmoothTheEdgesAndTheLayerStillEqualsAFullRedraw) {
  std::vector<int32_t> moving;
  bumped(0.0, &moving);
  FrameView view;
  view.vertices_m = &rest_.vertices_m;
  view.triangles = &rest_.triangles;
  std::vector<uint8_t> one(static_cast<std::size_t>(kW) * kH * 4), four(one.size()), full(one.size());
  auto between = [](const std::vector<uint8_t>& rgba) {
    // the background, and the sheet's one colour (its centre pixel)
    const auto inside = pixel(rgba, kW, kW / 2, kH / 2);
    int n = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const auto p = pixel(rgba, kW, x, y);
        const bool bg = p[0] == 247 && p[1] == 247 && p[2] == 250;
        const bool sheet = p[0] == inside[0] && p[1] == inside[1] && p[2] == inside[2];
        n += bg || sheet ? 0 : 1;
      }
    return n;
  };
  Renderer single(ctx_.get(), RenderStyle::kSolid, camera_);
  single.draw(view, one.data());
  EXPECT_EQ(single.samples(), 0);
  EXPECT_EQ(between(one), 0);
  Renderer layered(ctx_.get(), RenderStyle::kSolid, camera_), whole(ctx_.get(), RenderStyle::kSolid, camera_);
  layered.set_samples(4);
  whole.set_samples(4);
  whole.set_layered(false);
  view.moving_vertices = &moving;
  view.layer_epoch = 1;
  for (double h : {0.0, 0.004}) {
    const std::vector<Vec3> v = bumped(h);
    view.vertices_m = &v;
    layered.draw(view, four.data());
    whole.draw(view, full.data());
    EXPECT_EQ(test::count_different(four, full), 0) << "bump " << h;
  }
  ASSERT_EQ(layered.samples(), 4);
  view.vertices_m = &rest_.vertices_m;
  Renderer flat(ctx_.get(), RenderStyle::kSolid, camera_);
  flat.set_samples(4);
  flat.draw(view, four.data());
  // the sheet's outline is a few hundred pixels long: most of them are now between
  EXPECT_GT(between(four), 150);
}

// Edges smoothed in the image read back (the default of a recording): the sheet's outline gets colours between the
// background's and the sheet's, as multisampling gives it, and frames from the cached layer still equal full redraws.
TEST_F(AnnotateRender, EdgesSmoothedInTheImageSoftenTheOutlineAndTheLayerStillEqualsAFullRedraw) {
  std::vector<int32_t> moving;
  bumped(0.0, &moving);
  FrameView view;
  view.triangles = &rest_.triangles;
  view.moving_vertices = &moving;
  view.layer_epoch = 1;
  std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size()), plain(a.size());
  Renderer layered(ctx_.get(), RenderStyle::kSolid, camera_), whole(ctx_.get(), RenderStyle::kSolid, camera_),
      unsmoothed(ctx_.get(), RenderStyle::kSolid, camera_);
  layered.set_smooth_edges(true);
  whole.set_smooth_edges(true);
  whole.set_layered(false);
  for (double h : {0.0, 0.004, 0.004, 0.006}) {
    const std::vector<Vec3> v = bumped(h);
    view.vertices_m = &v;
    layered.draw(view, a.data());
    whole.draw(view, b.data());
    EXPECT_EQ(test::count_different(a, b), 0) << "bump " << h;
  }
  view.vertices_m = &rest_.vertices_m;
  layered.draw(view, a.data());
  unsmoothed.draw(view, plain.data());
  // pixels that are neither the background nor the sheet's colour at its centre: on the outline
  auto between = [](const std::vector<uint8_t>& rgba) {
    const auto inside = pixel(rgba, kW, kW / 2, kH / 2);
    int n = 0;
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const auto p = pixel(rgba, kW, x, y);
        const bool bg = p[0] == 247 && p[1] == 247 && p[2] == 250;
        n += bg || (std::abs(p[0] - inside[0]) + std::abs(p[1] - inside[1]) + std::abs(p[2] - inside[2]) < 6) ? 0 : 1;
      }
    return n;
  };
  EXPECT_EQ(between(plain), 0);
  EXPECT_GT(between(a), 150);
  EXPECT_TRUE(layered.smooth_edges());
}

// Coloured by strain: a value per vertex, the map's top at the vertex whose value reaches the range, the legend's bar
// beside it; without values the sheet is one colour.
TEST_F(AnnotateRender, StrainColoursPutTheMapsTopAtTheMostStrainedVertex) {
  const std::vector<Vec3> v = bumped(0.004);
  std::vector<float> strain(v.size(), 0.0f);
  for (std::size_t i = 0; i < v.size(); ++i)
    strain[i] = static_cast<float>(0.1 * std::exp(-(rest_.vertices_m[i] - Vec3(0.01, -0.01, 0)).squaredNorm() / (2 * 0.006 * 0.006)));
  FrameView view;
  view.vertices_m = &v;
  view.triangles = &rest_.triangles;
  view.rest_m = &rest_.vertices_m;
  view.vertex_value = &strain;
  view.strain_range = 0.1;
  view.show_legend = true;
  Renderer renderer(ctx_.get(), RenderStyle::kSolid, camera_);
  std::vector<uint8_t> rgba(static_cast<std::size_t>(kW) * kH * 4);
  renderer.draw(view, rgba.data());
  // the strain's peak, away from the bump's apex, is red; the apex (displaced, little strain) is not
  std::size_t peak = 0;
  for (std::size_t i = 0; i < strain.size(); ++i)
    if (strain[i] > strain[peak]) peak = i;
  const Eigen::Vector2d at_peak = renderer.project(v[peak]);
  const Eigen::Vector2d apex = renderer.project(v[20 * 41 + 20]);
  EXPECT_GT(redness(pixel(rgba, kW, static_cast<int>(at_peak.x()), static_cast<int>(at_peak.y()))), 60);
  EXPECT_LT(redness(pixel(rgba, kW, static_cast<int>(apex.x()), static_cast<int>(apex.y()))),
            redness(pixel(rgba, kW, static_cast<int>(at_peak.x()), static_cast<int>(at_peak.y()))) - 40);
  int top_color_px = 0;
  for (int y = 0; y < kH / 2; ++y)
    for (int x = kW / 2; x < kW; ++x) {
      const auto p = pixel(rgba, kW, x, y);
      top_color_px += p[0] == 176 && p[1] == 26 && p[2] == 30;
    }
  EXPECT_GT(top_color_px, 0);
  EXPECT_EQ(format_percent(0.1), "10 %");
  EXPECT_EQ(format_percent(0.005), "0.5 %");
}

// The insets go where the model is not: with the sheet filling the left half of the picture, the force trace leaves
// the bottom-left corner for the bottom-right one and the legend keeps the top-right; the model's pixels under the
// default corner stay the model's.
TEST_F(AnnotateRender, TheInsetsTakeTheCornersTheModelLeavesFree) {
  const std::vector<float> trace(60, 1.0f);
  FrameView view;
  view.vertices_m = &rest_.vertices_m;
  view.triangles = &rest_.triangles;
  view.rest_m = &rest_.vertices_m;
  view.color_range_m = 0.01;
  view.show_legend = true;
  view.force_scale_N = 3.0;
  view.force_trace = &trace;
  view.force_trace_max_N = 2.0;
  view.force_trace_frames = 120;
  std::vector<uint8_t> rgba(static_cast<std::size_t>(kW) * kH * 4);
  Renderer whole(ctx_.get(), RenderStyle::kSolid, camera_);
  whole.draw(view, rgba.data());
  EXPECT_EQ(whole.legend_corner(), Corner::kTopRight);
  EXPECT_EQ(whole.trace_corner(), Corner::kBottomLeft);
  // from above, the sheet's right edge at the picture's centre: the sheet fills the left half
  const Camera half = Camera::framing_part(Vec3(-0.03, -0.03, 0.0), Vec3(0.03, 0.03, 0.0), static_cast<double>(kW) / kH,
                                           Vec3(0, 0, 1), Vec3(0.03, 0.0, 0.0), 0.03);
  Renderer left(ctx_.get(), RenderStyle::kSolid, half);
  left.draw(view, rgba.data());
  EXPECT_EQ(left.legend_corner(), Corner::kTopRight);
  EXPECT_EQ(left.trace_corner(), Corner::kBottomRight);
  // the trace's line (its orange, drawn unlit) is on the right, and the sheet still shows at the bottom-left
  int orange_left = 0, orange_right = 0;
  for (int y = kH / 2; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const auto p = pixel(rgba, kW, x, y);
      if (p[0] == 230 && p[1] == 110 && p[2] == 0) (x < kW / 2 ? orange_left : orange_right)++;
    }
  EXPECT_EQ(orange_left, 0);
  EXPECT_GT(orange_right, 20);
  const auto corner = pixel(rgba, kW, 12, kH - 12);
  EXPECT_FALSE(corner[0] == 247 && corner[1] == 247 && corner[2] == 250);  // not the background: the sheet
  EXPECT_LT(corner[0], 225);  // nor the trace's white paper over it
}

// The arrow's pixels (its colour, unlit): the farthest from the proxy's pixel.
double arrow_reach_px(const std::vector<uint8_t>& rgba, const Eigen::Vector2d& from) {
  double most = 0.0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const auto p = pixel(rgba, kW, x, y);
      if (std::abs(p[0] - 230) <= 2 && std::abs(p[1] - 110) <= 2 && p[2] <= 2)
        most = std::max(most, std::hypot(x - from.x(), y - from.y()));
    }
  return most;
}

TEST_F(AnnotateRender, TheArrowsLengthFollowsTheForce) {
  FrameView view;
  view.vertices_m = &rest_.vertices_m;
  view.triangles = &rest_.triangles;
  view.show_force = true;
  view.force_scale_N = 4.0;
  view.proxy_pos_m = Vec3(-0.01, 0.0, 0.0);
  Renderer renderer(ctx_.get(), RenderStyle::kSolid, camera_);
  const Eigen::Vector2d at = renderer.project(view.proxy_pos_m);
  std::vector<uint8_t> rgba(static_cast<std::size_t>(kW) * kH * 4);
  std::vector<double> reach;
  // across the view (the camera's right) and up out of the sheet
  const Vec3 right = (camera_.target_m - camera_.eye_m).cross(camera_.up).normalized();
  for (const Vec3& dir : {right, Vec3(0, 0, 1)}) {
    for (double f : {1.0, 2.0, 4.0}) {
      view.force_N = f * dir;
      renderer.draw(view, rgba.data());
      reach.push_back(arrow_reach_px(rgba, at));
    }
    const std::size_t k = reach.size() - 3;
    EXPECT_GT(reach[k], 5.0);
    if (dir.z() == 0.0) {
      // across the view: linear in the force (from 2 N to 4 N twice what it grows from 1 N to 2 N; the pixels
      // at the head's point, which a raster drops, make every arrow a pixel or two short)
      EXPECT_NEAR((reach[k + 2] - reach[k + 1]) / (reach[k + 1] - reach[k]), 2.0, 0.25)
          << reach[k] << " " << reach[k + 1] << " " << reach[k + 2];
    } else {
      // toward the eye: foreshortened, and nearer the eye as it grows (perspective), so only ever longer
      EXPECT_GT(reach[k + 1], 1.5 * reach[k]);
      EXPECT_GT(reach[k + 2], 1.5 * reach[k + 1]);
    }
  }
  // the force limit's arrow spans a fifth of the picture's height where the proxy is (drawn across the view)
  EXPECT_NEAR(reach[2], 0.2 * kH, 0.05 * kH);
  // no force, no arrow
  view.force_N = Vec3::Zero();
  renderer.draw(view, rgba.data());
  EXPECT_EQ(arrow_reach_px(rgba, at), 0.0);
}

TEST_F(AnnotateRender, FacesACutMadeCarryTheCutsColour) {
  // the triangles of the sheet's middle row of quads re-made on vertices appended after the model's own (as a cut's
  // split appends them), at the same places
  TriMesh cut = rest_;
  const auto first_cut = static_cast<int64_t>(cut.vertices_m.size());
  for (auto& t : cut.triangles) {
    const Vec3 c = (cut.vertices_m[t[0]] + cut.vertices_m[t[1]] + cut.vertices_m[t[2]]) / 3.0;
    if (std::abs(c.y()) > 0.004) continue;
    for (int32_t& i : t) {
      cut.vertices_m.push_back(cut.vertices_m[i]);
      i = static_cast<int32_t>(cut.vertices_m.size()) - 1;
    }
  }
  FrameView view;
  view.vertices_m = &cut.vertices_m;
  view.triangles = &cut.triangles;
  view.rest_m = &cut.vertices_m;
  view.first_cut_vertex = first_cut;
  Renderer renderer(ctx_.get(), RenderStyle::kSolid, camera_);
  std::vector<uint8_t> rgba(static_cast<std::size_t>(kW) * kH * 4);
  renderer.draw(view, rgba.data());
  const auto on_cut = pixel(rgba, kW, static_cast<int>(renderer.project(Vec3(0.0, 0.0, 0.0)).x()),
                            static_cast<int>(renderer.project(Vec3(0.0, 0.0, 0.0)).y()));
  const Eigen::Vector2d off = renderer.project(Vec3(0.0, 0.02, 0.0));
  const auto beside = pixel(rgba, kW, static_cast<int>(off.x()), static_cast<int>(off.y()));
  // magenta-red where the cut's faces are: red and blue both well above green; the model's blue-grey beside them
  EXPECT_GT(on_cut[0] - on_cut[1], 60) << on_cut[0] << " " << on_cut[1] << " " << on_cut[2];
  EXPECT_GT(on_cut[2] - on_cut[1], 20) << on_cut[0] << " " << on_cut[1] << " " << on_cut[2];
  EXPECT_LT(beside[0] - beside[1], 10) << beside[0] << " " << beside[1] << " " << beside[2];
}

}  // namespace
}  // namespace palpate
