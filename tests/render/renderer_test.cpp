#include "render/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "core/aabb.h"
#include "core/mesh_io.h"
#include "render/gl_context_factory.h"
#include "render_test_util.h"

namespace palpate {
namespace {

using test::count_different;

constexpr int kW = 160;
constexpr int kH = 120;

using test::pixel;

bool is_background(const std::array<int, 4>& p) {
  // clear colour (0.97, 0.97, 0.98)
  return std::abs(p[0] - 247) <= 2 && std::abs(p[1] - 247) <= 2 && std::abs(p[2] - 250) <= 2;
}

bool is_red(const std::array<int, 4>& p) { return p[0] > 170 && p[1] < 90 && p[2] < 90; }

class RendererTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    auto ctx = create_gl_context(kW, kH, from_name<RenderBackend>(GetParam()).value());
    if (!ctx.ok()) {
      const std::string& m = ctx.error().message;
      if (GetParam() == "egl" && m.find("not available") != std::string::npos) GTEST_SKIP() << m;
      FAIL() << m;
    }
    ctx_ = std::move(ctx.value());
    box_ = test::make_box_mesh(lo_, hi_);
    camera_ = Camera::framing(lo_, hi_, static_cast<double>(kW) / kH);
    view_.vertices_m = &box_.vertices_m;
    view_.triangles = &box_.triangles;
  }

  std::vector<uint8_t> render(RenderStyle style, const FrameView& view) {
    Renderer renderer(ctx_.get(), style, camera_);
    std::vector<uint8_t> rgba(static_cast<std::size_t>(kW) * kH * 4, 0);
    renderer.draw(view, rgba.data());
    return rgba;
  }

  Eigen::Vector2d project(const Vec3& p) {
    Renderer renderer(ctx_.get(), RenderStyle::kSolid, camera_);
    return renderer.project(p);
  }

  const Vec3 lo_ = Vec3(-0.05, -0.04, 0.0);
  const Vec3 hi_ = Vec3(0.05, 0.04, 0.06);
  std::unique_ptr<GlContext> ctx_;
  TriMesh box_;
  Camera camera_;
  FrameView view_;
};

TEST_P(RendererTest, BoxCoversItsCentreAndLeavesCornersBackground) {
  const auto rgba = render(RenderStyle::kSolid, view_);
  const Eigen::Vector2d c = project(0.5 * (lo_ + hi_));
  const auto centre = pixel(rgba, kW, int(c.x()), int(c.y()));
  EXPECT_FALSE(is_background(centre)) << centre[0] << " " << centre[1] << " " << centre[2];
  EXPECT_EQ(centre[3], 255);
  for (const auto& [x, y] : {std::pair{0, 0}, {kW - 1, 0}, {0, kH - 1}, {kW - 1, kH - 1}}) {
    const auto p = pixel(rgba, kW, x, y);
    EXPECT_TRUE(is_background(p)) << "(" << x << "," << y << ") = " << p[0] << " " << p[1] << " " << p[2];
  }
}

TEST_P(RendererTest, ToolSphereIsRedInContactAndBlueOtherwise) {
  FrameView view = view_;
  view.tool_pos_m = 0.5 * (lo_ + hi_) + Vec3(0.0, 0.0, 0.05);  // above the top face
  view.tool_radius_m = 0.012;
  const Eigen::Vector2d t = project(view.tool_pos_m);
  const Eigen::Vector2d c = project(0.5 * (lo_ + hi_));
  ASSERT_LT(t.y(), c.y() - 5);  // the tool is above the box centre in the image
  const int tx = int(t.x()), ty = int(t.y());

  view.in_contact = true;
  const auto contact = render(RenderStyle::kSolid, view);
  const auto p = pixel(contact, kW, tx, ty);
  EXPECT_TRUE(is_red(p)) << p[0] << " " << p[1] << " " << p[2];
  // rows are top-down: the mirrored row shows no tool
  EXPECT_FALSE(is_red(pixel(contact, kW, tx, kH - 1 - ty)));

  view.in_contact = false;
  const auto free = render(RenderStyle::kSolid, view);
  const auto q = pixel(free, kW, tx, ty);
  EXPECT_FALSE(is_red(q));
  EXPECT_GT(q[2], q[0] + 60) << q[0] << " " << q[1] << " " << q[2];
}

TEST_P(RendererTest, WireframeSolidAndBothDiffer) {
  const auto solid = render(RenderStyle::kSolid, view_);
  const auto wire = render(RenderStyle::kWireframe, view_);
  const auto both = render(RenderStyle::kBoth, view_);
  const int min_diff = kW * kH / 100;
  EXPECT_GT(count_different(solid, wire), min_diff);
  EXPECT_GT(count_different(solid, both), min_diff / 4);
  EXPECT_GT(count_different(wire, both), min_diff);
  int bg_solid = 0, bg_wire = 0, bg_both = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      bg_solid += is_background(pixel(solid, kW, x, y));
      bg_wire += is_background(pixel(wire, kW, x, y));
      bg_both += is_background(pixel(both, kW, x, y));
    }
  }
  EXPECT_GT(bg_wire, bg_solid + min_diff);  // a wireframe leaves the faces open
  // lines lie on the surface: the outline grows by at most the silhouette's line pixels
  EXPECT_LE(bg_both, bg_solid);
  EXPECT_LT(bg_solid - bg_both, kW * kH / 50);
  // the polygon offset keeps the visible edges whole (about 73 % of all line pixels here; 44 % without it)
  const int line_pixels_all = kW * kH - bg_wire;
  const int line_pixels_visible = count_different(solid, both);
  EXPECT_GT(line_pixels_visible, line_pixels_all * 3 / 5)
      << "visible " << line_pixels_visible << " of " << line_pixels_all;
  EXPECT_LT(line_pixels_visible, line_pixels_all);
}

TEST_P(RendererTest, ProxySpringIsDrawnOnlyWhenAsked) {
  FrameView view = view_;
  view.tool_pos_m = Vec3(0.0, -0.02, 0.09);
  view.tool_radius_m = 0.006;
  view.proxy_pos_m = Vec3(0.0, -0.02, 0.06);  // on the top face
  const auto hidden = render(RenderStyle::kSolid, view);
  view.show_proxy = true;
  const auto shown = render(RenderStyle::kSolid, view);
  EXPECT_GT(count_different(hidden, shown), 10);
  const Eigen::Vector2d p = project(view.proxy_pos_m);
  const auto dot = pixel(shown, kW, int(p.x()), int(p.y()));
  EXPECT_GT(dot[1], dot[0] + 40) << dot[0] << " " << dot[1] << " " << dot[2];  // green
  EXPECT_GT(dot[1], dot[2] + 40) << dot[0] << " " << dot[1] << " " << dot[2];
}

TEST_P(RendererTest, BladeIsDrawnAsADarkLineOnlyWhenAsked) {
  FrameView view = view_;
  view.blade_tip_m = Vec3(-0.03, -0.07, 0.02);  // in front of the box, not hidden by it
  view.blade_end_m = Vec3(0.03, -0.07, 0.08);
  const auto hidden = render(RenderStyle::kSolid, view);
  view.show_blade = true;
  const auto shown = render(RenderStyle::kSolid, view);
  EXPECT_GT(count_different(hidden, shown), 40);
  const Eigen::Vector2d a = project(view.blade_tip_m), b = project(view.blade_end_m);
  for (int i = 1; i < 10; ++i) {
    const Eigen::Vector2d p = a + (i / 10.0) * (b - a);
    const auto px = pixel(shown, kW, int(std::lround(p.x())), int(std::lround(p.y())));
    EXPECT_LT(std::max({px[0], px[1], px[2]}), 60) << "at " << i << ": " << px[0] << " " << px[1] << " " << px[2];
  }
}

// A free tool above the box's top face: its drop line runs from it down to the face, and a dark disc marks where it
// lands; only when asked.
TEST_P(RendererTest, DropLineAndItsDiscShowWhereAFreeToolWouldLand) {
  FrameView view = view_;
  view.tool_pos_m = Vec3(0.0, -0.02, 0.11);
  view.tool_radius_m = 0.004;
  view.drop_to_m = Vec3(0.0, -0.02, 0.06);  // on the top face, straight below
  view.drop_normal = Vec3::UnitZ();
  const auto hidden = render(RenderStyle::kSolid, view);
  view.show_drop = true;
  const auto shown = render(RenderStyle::kSolid, view);
  EXPECT_GT(count_different(hidden, shown), 20);
  const Eigen::Vector2d a = project(view.tool_pos_m), b = project(view.drop_to_m);
  // the line between the tool's edge and the face: a dark grey pixel where the picture was lighter (a 1 px line:
  // the darkest of the 3 x 3 around each point)
  auto darkest = [](const std::vector<uint8_t>& rgba, const Eigen::Vector2d& p) {
    int v = 255;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const auto px = pixel(rgba, kW, int(std::lround(p.x())) + dx, int(std::lround(p.y())) + dy);
        v = std::min(v, std::max({px[0], px[1], px[2]}));
      }
    return v;
  };
  for (int i = 4; i < 9; ++i) {
    const Eigen::Vector2d p = a + (i / 10.0) * (b - a);
    EXPECT_LT(darkest(shown, p), 110) << "at " << i;
    EXPECT_GT(darkest(hidden, p), darkest(shown, p) + 20) << "at " << i;
  }
  // the disc where it lands
  const auto d = pixel(shown, kW, int(std::lround(b.x())), int(std::lround(b.y())));
  EXPECT_LT(std::max({d[0], d[1], d[2]}), 60) << d[0] << " " << d[1] << " " << d[2];
}

// A tool pressed into the box (its centre under the top face) is hidden by the face in a solid drawing; its outline
// is drawn through the face in the tool's colour.
TEST_P(RendererTest, AToolInsideTheSurfaceShowsItsOutlineThroughIt) {
  FrameView view = view_;
  view.tool_pos_m = Vec3(0.0, -0.02, 0.05);  // 1 cm under the top face
  view.tool_radius_m = 0.008;
  view.in_contact = true;
  const auto with_tool = render(RenderStyle::kSolid, view);
  FrameView none = view_;
  const auto without = render(RenderStyle::kSolid, none);
  const Eigen::Vector2d t = project(view.tool_pos_m);
  int red = 0;
  for (int dy = -4; dy <= 4; ++dy)
    for (int dx = -4; dx <= 4; ++dx) red += is_red(pixel(with_tool, kW, int(t.x()) + dx, int(t.y()) + dy)) ? 1 : 0;
  EXPECT_GT(red, 5) << "no outline of the hidden tool";
  EXPECT_GT(count_different(with_tool, without), 10);
}

TEST_P(RendererTest, SameFrameTwiceIsIdentical) {
  FrameView view = view_;
  view.tool_pos_m = Vec3(0.02, -0.05, 0.04);
  view.tool_radius_m = 0.01;
  Renderer renderer(ctx_.get(), RenderStyle::kBoth, camera_);
  std::vector<uint8_t> a(kW * kH * 4), b(kW * kH * 4);
  renderer.draw(view, a.data());
  renderer.draw(view, b.data());
  EXPECT_EQ(a, b);
  // of a drawn frame, not a blank one: the box covers its centre and the background shows at a corner
  const Eigen::Vector2d c = project(0.5 * (lo_ + hi_));
  EXPECT_FALSE(is_background(pixel(a, kW, int(c.x()), int(c.y()))));
  EXPECT_TRUE(is_background(pixel(a, kW, 0, 0)));
}

TEST_P(RendererTest, GivenNormalsAreUsedAndBadIndicesAreSkipped) {
  // normals handed in equal to the computed ones give the same image; flipped ones light the box from
  // behind (one-sided light: darker), so the given array is what the renderer shades with
  std::vector<Vec3> normals;
  compute_vertex_normals(box_.vertices_m, box_.triangles, &normals);
  FrameView view = view_;
  view.normals = &normals;
  const auto computed = render(RenderStyle::kSolid, view_);
  EXPECT_EQ(render(RenderStyle::kSolid, view), computed);
  for (Vec3& n : normals) n = -n;
  const auto flipped = render(RenderStyle::kSolid, view);
  const Eigen::Vector2d mid = project(0.5 * (lo_ + hi_));
  const auto lit = pixel(computed, kW, int(mid.x()), int(mid.y()));
  const auto dark = pixel(flipped, kW, int(mid.x()), int(mid.y()));
  EXPECT_LT(dark[0] + dark[1] + dark[2] + 30, lit[0] + lit[1] + lit[2]);

  TriMesh bad = box_;
  bad.triangles[3][1] = 8;  // one past the last vertex
  view = view_;
  view.triangles = &bad.triangles;
  const auto skipped = render(RenderStyle::kSolid, view);
  const Eigen::Vector2d c = project(0.5 * (lo_ + hi_));
  EXPECT_TRUE(is_background(pixel(skipped, kW, int(c.x()), int(c.y()))));
}

// The cached static layer plus what moves gives the pixels of a full redraw, frame after frame, through a
// change of the moving set, in every style; the layered renderer really uses its layer.
TEST_P(RendererTest, CachedLayerGivesTheFullRedrawsPixels) {
  TriMesh mesh = ::palpate::make_box_mesh(Vec3(0.1, 0.08, 0.06), 10);
  const std::vector<Vec3> rest = mesh.vertices_m;
  const Aabb box = Aabb::of(rest);
  const Camera cam = Camera::framing(box.min_m, box.max_m, static_cast<double>(kW) / kH);
  for (RenderStyle style : {RenderStyle::kBoth, RenderStyle::kSolid, RenderStyle::kWireframe}) {
    Renderer layered(ctx_.get(), style, cam), full(ctx_.get(), style, cam);
    full.set_layered(false);
    std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size());
    std::vector<int32_t> moving;
    std::vector<Vec3> normals;
    int64_t frames = 0, differing_frames = 0, layered_frames = 0;
    for (int epoch = 0; epoch < 2; ++epoch) {
      // the moving set: a corner of the box, then the opposite side
      moving.clear();
      for (std::size_t v = 0; v < rest.size(); ++v)
        if ((epoch == 0 && rest[v].x() > 0.02 && rest[v].z() > 0.0) || (epoch == 1 && rest[v].x() < -0.02))
          moving.push_back(static_cast<int32_t>(v));
      ASSERT_GT(moving.size(), 10u);
      for (int f = 0; f < 6; ++f) {
        // pressed in and sheared, more each frame, so moving triangles pass in front of and behind static ones
        for (int32_t v : moving) {
          const Vec3& r = rest[v];
          mesh.vertices_m[v] = r + (f + 1) * Vec3(-0.004 * std::cos(40 * r.y()), 0.003 * r.z() * 30, -0.002);
        }
        compute_vertex_normals(mesh.vertices_m, mesh.triangles, &normals);
        FrameView view{};
        view.vertices_m = &mesh.vertices_m;
        view.triangles = &mesh.triangles;
        view.normals = &normals;
        view.tool_pos_m = mesh.vertices_m[moving.front()] + Vec3(0, 0, 0.004);
        view.tool_radius_m = 0.006;
        view.in_contact = true;
        view.show_proxy = true;
        view.proxy_pos_m = mesh.vertices_m[moving.front()];
        view.moving_vertices = &moving;
        view.layer_epoch = static_cast<uint64_t>(epoch);
        layered.draw(view, a.data());
        layered_frames += layered.last_draw_layered() ? 1 : 0;
        full.draw(view, b.data());
        EXPECT_FALSE(full.last_draw_layered());
        ++frames;
        differing_frames += a != b ? 1 : 0;
        EXPECT_EQ(count_different(a, b), 0) << "style " << static_cast<int>(style) << " epoch " << epoch << " frame " << f;
      }
    }
    EXPECT_EQ(differing_frames, 0);
    EXPECT_EQ(layered_frames, frames);
    EXPECT_EQ(layered.layer_builds(), 2);  // once per epoch
    // a frame that moves nothing differs from one that moved: the comparison above is not of blank images
    std::vector<uint8_t> at_rest(a.size());
    FrameView rest_view{};
    rest_view.vertices_m = &rest;
    rest_view.triangles = &mesh.triangles;
    full.draw(rest_view, at_rest.data());
    EXPECT_GT(count_different(at_rest, a), 100);
  }
}

// Flips the diagonal of every quad (triangles 2q, 2q + 1 of a box mesh) whose four corners pass `in`: the same
// vertices and triangle count, other triangles (a topology change only the epoch can tell).
template <class In>
void flip_quads(const std::vector<Vec3>& rest, std::vector<std::array<int32_t, 3>>* triangles, In in) {
  for (std::size_t q = 0; q + 1 < triangles->size(); q += 2) {
    auto& t0 = (*triangles)[q];
    auto& t1 = (*triangles)[q + 1];
    // t0 = (p, s1, s2) with p not in t1; then t1 = (r, s2, s1)
    int k = 0;
    while (k < 3 && std::find(t1.begin(), t1.end(), t0[k]) != t1.end()) ++k;
    ASSERT_LT(k, 3);
    const int32_t p = t0[k], s1 = t0[(k + 1) % 3], s2 = t0[(k + 2) % 3];
    int32_t r = -1;
    for (int32_t v : t1)
      if (v != s1 && v != s2) r = v;
    ASSERT_GE(r, 0);
    if (!in(rest[p]) || !in(rest[s1]) || !in(rest[s2]) || !in(rest[r])) continue;
    t0 = {p, s1, r};
    t1 = {p, r, s2};
  }
}

// The dynamic part is drawn from its own compact vertex array: after the moving set changes, after a topology
// change with the same counts and after one with new counts, and with normals computed by the renderer (the
// view gives none), every frame has the pixels of a full redraw.
TEST_P(RendererTest, CompactDynamicArrayKeepsTheFullRedrawsPixels) {
  TriMesh mesh = ::palpate::make_box_mesh(Vec3(0.1, 0.08, 0.06), 8);
  const Aabb box = Aabb::of(mesh.vertices_m);
  const Camera cam = Camera::framing(box.min_m, box.max_m, static_cast<double>(kW) / kH);
  Renderer layered(ctx_.get(), RenderStyle::kBoth, cam), full(ctx_.get(), RenderStyle::kBoth, cam);
  full.set_layered(false);
  std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size()), first(a.size());
  std::vector<int32_t> moving;
  std::vector<Vec3> rest;
  int64_t frames = 0, layered_frames = 0, changed = 0;
  for (int epoch = 0; epoch < 4; ++epoch) {
    // 0: a corner; 1: the opposite side; 2: its quads' diagonals flipped; 3: the mesh subdivided
    auto in_region = [epoch](const Vec3& r) { return epoch == 0 ? r.x() > 0.02 && r.z() > 0.0 : r.x() < -0.02; };
    if (epoch == 2) flip_quads(mesh.vertices_m, &mesh.triangles, in_region);
    if (epoch == 3) mesh = subdivide_midpoint(mesh);
    rest = mesh.vertices_m;
    moving.clear();
    for (std::size_t v = 0; v < rest.size(); ++v)
      if (in_region(rest[v])) moving.push_back(static_cast<int32_t>(v));
    ASSERT_GT(moving.size(), 10u);
    for (int f = 0; f < 4; ++f) {
      for (int32_t v : moving) {
        const Vec3& r = rest[v];
        mesh.vertices_m[v] = r + (f + 1) * Vec3(0.003 * std::sin(50 * r.y()), 0.002 * std::cos(40 * r.z()), -0.003);
      }
      FrameView view{};
      view.vertices_m = &mesh.vertices_m;
      view.triangles = &mesh.triangles;
      view.moving_vertices = &moving;
      view.layer_epoch = static_cast<uint64_t>(epoch);
      layered.draw(view, a.data());
      layered_frames += layered.last_draw_layered() ? 1 : 0;
      full.draw(view, b.data());
      EXPECT_EQ(count_different(a, b), 0) << "epoch " << epoch << " frame " << f;
      if (frames == 0) first = a;
      changed += count_different(first, a) > 100 ? 1 : 0;
      ++frames;
    }
  }
  EXPECT_EQ(layered_frames, frames);
  EXPECT_EQ(layered.layer_builds(), 4);
  EXPECT_GE(changed, frames / 2);  // the frames compared show a moving mesh
}

// A box finer than the image (about 1 px edges at 160 x 120): most of its triangles fall between pixel centres.
TriMesh dense_box() { return subdivide_midpoint(subdivide_midpoint(::palpate::make_box_mesh(Vec3(0.1, 0.08, 0.06), 24))); }

// On a mesh finer than the image the layered path leaves out most of what moves (it covers no pixel centre),
// and every frame still has the pixels of a full redraw, filled and with the wireframe drawn; with culling off
// the layered path draws everything and gives the same pixels.
TEST_P(RendererTest, DenseMeshLeavesOutWhatCoversNoPixelAndKeepsTheFullRedrawsPixels) {
  TriMesh mesh = dense_box();
  const std::vector<Vec3> rest = mesh.vertices_m;
  const Aabb box = Aabb::of(rest);
  const Camera cam = Camera::framing(box.min_m, box.max_m, static_cast<double>(kW) / kH);
  std::vector<int32_t> moving;
  for (std::size_t v = 0; v < rest.size(); ++v)
    if (rest[v].x() > 0.0 && rest[v].z() > 0.0) moving.push_back(static_cast<int32_t>(v));
  for (RenderStyle style : {RenderStyle::kSolid, RenderStyle::kBoth}) {
    Renderer layered(ctx_.get(), style, cam), unculled(ctx_.get(), style, cam), full(ctx_.get(), style, cam);
    for (Renderer* r : {&layered, &unculled, &full}) r->set_wire_min_edge_px(0.0);  // lines drawn, however fine
    unculled.set_culling(false);
    full.set_layered(false);
    std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size()), c(a.size()), first(a.size());
    int changed = 0;
    for (int f = 0; f < 4; ++f) {
      for (int32_t v : moving) {
        const Vec3& r = rest[v];
        mesh.vertices_m[v] = r + (f + 1) * Vec3(0.002 * std::sin(60 * r.y()), 0.0015 * std::cos(50 * r.z()), -0.002);
      }
      FrameView view{};
      view.vertices_m = &mesh.vertices_m;
      view.triangles = &mesh.triangles;
      view.moving_vertices = &moving;
      layered.draw(view, a.data());
      unculled.draw(view, c.data());
      full.draw(view, b.data());
      ASSERT_TRUE(layered.last_draw_layered());
      EXPECT_EQ(count_different(a, b), 0) << "style " << static_cast<int>(style) << " frame " << f;
      EXPECT_EQ(count_different(c, b), 0) << "style " << static_cast<int>(style) << " frame " << f;
      // most moving triangles cover no centre and are left out; lines on screen are all kept
      const Renderer::Drawn& d = layered.last_drawn();
      EXPECT_GT(d.triangles, 10000u);
      EXPECT_LT(d.triangles_drawn, d.triangles * 7 / 10) << "frame " << f;
      EXPECT_EQ(unculled.last_drawn().triangles_drawn, d.triangles);
      if (style == RenderStyle::kBoth) {
        EXPECT_GT(d.lines_drawn, d.lines / 2);
      }
      if (f == 0) first = a;
      changed += count_different(first, a) > 50 ? 1 : 0;
    }
    EXPECT_EQ(changed, 3);  // the frames moved: the comparison is not of one still image
  }
}

// `both` leaves out a wireframe whose median edge is shorter than render.wire_min_edge_px (2 px by default):
// on the dense box the frame is the solid style's, pixel for pixel; with the threshold at 0 the lines are
// drawn; on a coarse box they are drawn by default.
TEST_P(RendererTest, BothLeavesOutAWireframeFinerThanTheImage) {
  const TriMesh mesh = dense_box();
  const Aabb box = Aabb::of(mesh.vertices_m);
  const Camera cam = Camera::framing(box.min_m, box.max_m, static_cast<double>(kW) / kH);
  FrameView view{};
  view.vertices_m = &mesh.vertices_m;
  view.triangles = &mesh.triangles;
  Renderer both(ctx_.get(), RenderStyle::kBoth, cam), solid(ctx_.get(), RenderStyle::kSolid, cam),
      always(ctx_.get(), RenderStyle::kBoth, cam);
  always.set_wire_min_edge_px(0.0);
  EXPECT_TRUE(std::isnan(both.median_edge_px()));  // not decided before a mesh is drawn
  std::vector<uint8_t> a(static_cast<std::size_t>(kW) * kH * 4), b(a.size()), c(a.size());
  both.draw(view, a.data());
  solid.draw(view, b.data());
  always.draw(view, c.data());
  EXPECT_FALSE(both.wire_drawn());
  EXPECT_GT(both.median_edge_px(), 0.3);
  EXPECT_LT(both.median_edge_px(), kWireMinEdgePxDefault);
  EXPECT_EQ(count_different(a, b), 0);
  EXPECT_TRUE(always.wire_drawn());
  EXPECT_GT(count_different(c, b), 1000);

  const TriMesh coarse = ::palpate::make_box_mesh(Vec3(0.1, 0.08, 0.06), 6);
  view.vertices_m = &coarse.vertices_m;
  view.triangles = &coarse.triangles;
  Renderer coarse_both(ctx_.get(), RenderStyle::kBoth, cam), coarse_solid(ctx_.get(), RenderStyle::kSolid, cam);
  coarse_both.draw(view, a.data());
  coarse_solid.draw(view, b.data());
  EXPECT_TRUE(coarse_both.wire_drawn());
  EXPECT_GT(coarse_both.median_edge_px(), kWireMinEdgePxDefault);
  EXPECT_GT(count_different(a, b), 500);
}

INSTANTIATE_TEST_SUITE_P(Backends, RendererTest, ::testing::Values("osmesa", "egl"),
                         [](const auto& param_info) { return param_info.param; });

}  // namespace
}  // namespace palpate
