#include "render/pixel_cover.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "render/gl_context.h"
#include "render/gl_context_factory.h"

namespace palpate {
namespace {

constexpr int kW = 64;
constexpr int kH = 48;

// world -> clip for world coordinates in pixels: x, y in GL window coordinates (origin bottom-left), z = 0
Eigen::Matrix4d window_ortho(int w, int h) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m(0, 0) = 2.0 / w;
  m(0, 3) = -1.0;
  m(1, 1) = 2.0 / h;
  m(1, 3) = -1.0;
  return m;
}

struct Prims {
  std::vector<float> positions;  // 3 per vertex, pixels
  std::vector<PixelCover::Cell> fill_cells, line_cells;
  std::vector<uint32_t> indices;
};

// Places n vertices (x, y pixel pairs) and their cells for fills and lines.
Prims place(const PixelCover& cover, const std::vector<float>& xy_in, std::vector<uint32_t> indices) {
  Prims p;
  const std::size_t n = xy_in.size() / 2;
  for (std::size_t i = 0; i < n; ++i) p.positions.insert(p.positions.end(), {xy_in[2 * i], xy_in[2 * i + 1], 0.0f});
  std::vector<float> xy(2 * n);
  cover.project(p.positions.data(), n, xy.data());
  p.fill_cells.resize(n);
  p.line_cells.resize(n);
  cover.cells(xy.data(), n, 0.0f, p.fill_cells.data());
  cover.cells(xy.data(), n, PixelCover::kLineReachPx, p.line_cells.data());
  p.indices = std::move(indices);
  return p;
}

bool keeps_triangle(const PixelCover& cover, std::vector<float> xy) {
  const Prims p = place(cover, xy, {0, 1, 2});
  std::vector<uint32_t> out;
  PixelCover::keep_triangles(p.fill_cells.data(), p.indices.data(), 3, &out);
  return out.size() == 3;
}

bool keeps_line(const PixelCover& cover, std::vector<float> xy) {
  const Prims p = place(cover, xy, {0, 1});
  std::vector<uint32_t> out;
  PixelCover::keep_lines(p.line_cells.data(), p.indices.data(), 2, &out);
  return out.size() == 2;
}

// Pixel centres are at half integers: a box between them is left out, one holding a centre, or reaching within
// the rounding margin of one, is kept; so is a primitive with a vertex that cannot be placed.
TEST(PixelCover, ATriangleIsKeptWhenItsBoxHoldsAPixelCentre) {
  PixelCover cover;
  cover.set(window_ortho(kW, kH), kW, kH);
  EXPECT_FALSE(keeps_triangle(cover, {10.6f, 5.6f, 11.4f, 5.7f, 10.8f, 6.4f}));   // between centres (10.5|11.5)
  EXPECT_TRUE(keeps_triangle(cover, {10.4f, 5.4f, 10.9f, 5.7f, 10.8f, 6.4f}));    // reaches (10.5, 5.5)
  EXPECT_TRUE(keeps_triangle(cover, {10.52f, 5.4f, 11.4f, 5.7f, 10.8f, 6.4f}));   // 0.02 px right of 10.5: margin
  EXPECT_FALSE(keeps_triangle(cover, {10.6f, 6.6f, 11.4f, 6.9f, 10.8f, 7.4f}));   // y between 6.5 and 7.5
  EXPECT_FALSE(keeps_triangle(cover, {-5.0f, 5.0f, -0.6f, 9.0f, -2.0f, 30.0f}));  // left of column 0
  EXPECT_TRUE(keeps_triangle(cover, {-5.0f, 5.0f, 0.6f, 9.0f, -2.0f, 30.0f}));    // reaches column 0's centre
  EXPECT_FALSE(keeps_triangle(cover, {70.0f, 5.0f, 90.0f, 9.0f, 80.0f, 30.0f}));  // right of the viewport
  EXPECT_TRUE(keeps_triangle(cover, {-1e30f, -1e30f, 1e30f, -1e30f, 0.0f, 1e30f}));  // covers everything
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_TRUE(keeps_triangle(cover, {10.6f, 5.6f, nan, 5.7f, 10.8f, 6.4f}));
}

// A 1-pixel line reaches centres half a pixel to either side, so on screen every line is kept (no point lies
// more than half a pixel from a row and a column of centres): only lines off the viewport are left out.
TEST(PixelCover, ALineIsLeftOutOnlyBeyondHalfAPixelOutsideTheViewport) {
  PixelCover cover;
  cover.set(window_ortho(kW, kH), kW, kH);
  EXPECT_TRUE(keeps_line(cover, {10.6f, 6.0f, 10.9f, 6.0f}));
  EXPECT_TRUE(keeps_line(cover, {-0.4f, 5.0f, 0.1f, 5.3f}));     // within reach of column 0 (0.5)
  EXPECT_FALSE(keeps_line(cover, {-1.2f, 5.0f, -0.7f, 5.3f}));   // 1.2 px left of column 0's centre
  EXPECT_FALSE(keeps_line(cover, {10.0f, 48.6f, 20.0f, 49.0f}));  // above the top row (47.5) by more than 0.5
  EXPECT_TRUE(keeps_line(cover, {10.0f, 47.9f, 20.0f, 49.0f}));
}

// The claim itself, checked against the real rasteriser: thousands of random triangles and lines of 0.05 to
// 1.5 px, many near or across the viewport's border; everything PixelCover leaves out is drawn in one call
// into a cleared frame, which must stay clear. What it keeps does draw (the check is not of an idle GL).
TEST(PixelCover, WhatIsLeftOutWritesNoPixelInTheRealRasteriser) {
  auto ctx_r = create_gl_context(kW, kH, RenderBackend::kOsmesa);
  ASSERT_TRUE(ctx_r.ok()) << ctx_r.error().message;
  std::unique_ptr<GlContext> ctx = std::move(ctx_r.value());
  ctx->make_current();
  const GlApi& gl = ctx->gl();
  const Eigen::Matrix4d vp = window_ortho(kW, kH);
  PixelCover cover;
  cover.set(vp, kW, kH);

  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-3.0f, kW + 3.0f), pos_y(-3.0f, kH + 3.0f), size(0.05f, 1.5f),
      unit(-1.0f, 1.0f);
  std::vector<float> xy;
  std::vector<uint32_t> tris, lines;
  for (uint32_t t = 0; t < 6000; ++t) {
    const float x = pos(rng), y = pos_y(rng), s = size(rng);
    for (int k = 0; k < 3; ++k) xy.insert(xy.end(), {x + s * unit(rng), y + s * unit(rng)});
    tris.insert(tris.end(), {3 * t, 3 * t + 1, 3 * t + 2});
    lines.insert(lines.end(), {3 * t, 3 * t + 1});
  }
  const Prims p = place(cover, xy, {});
  std::vector<uint32_t> kept_t, kept_l, dropped_t, dropped_l;
  PixelCover::keep_triangles(p.fill_cells.data(), tris.data(), tris.size(), &kept_t);
  PixelCover::keep_lines(p.line_cells.data(), lines.data(), lines.size(), &kept_l);
  // the complement, in the same order
  auto complement = [](const std::vector<uint32_t>& all, const std::vector<uint32_t>& kept, std::size_t arity) {
    std::vector<uint32_t> out;
    std::size_t j = 0;
    for (std::size_t i = 0; i < all.size(); i += arity) {
      if (j < kept.size() && kept[j] == all[i]) {
        j += arity;
        continue;
      }
      out.insert(out.end(), all.begin() + static_cast<std::ptrdiff_t>(i),
                 all.begin() + static_cast<std::ptrdiff_t>(i + arity));
    }
    return out;
  };
  dropped_t = complement(tris, kept_t, 3);
  dropped_l = complement(lines, kept_l, 2);
  ASSERT_EQ(dropped_t.size() + kept_t.size(), tris.size());
  ASSERT_EQ(dropped_l.size() + kept_l.size(), lines.size());
  // enough is left out for the check to mean something
  EXPECT_GT(dropped_t.size() / 3, 2000u);
  EXPECT_GT(dropped_l.size() / 2, 100u);

  auto draw = [&](GLenum mode, const std::vector<uint32_t>& idx) {
    gl.Viewport(0, 0, kW, kH);
    gl.ClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_LIGHTING);
    gl.MatrixMode(GL_PROJECTION);
    gl.LoadMatrixd(vp.data());
    gl.MatrixMode(GL_MODELVIEW);
    gl.LoadIdentity();
    gl.LineWidth(1.0f);
    gl.Color4f(1.0f, 1.0f, 1.0f, 1.0f);
    gl.EnableClientState(GL_VERTEX_ARRAY);
    gl.VertexPointer(3, GL_FLOAT, 0, p.positions.data());
    gl.DrawElements(mode, static_cast<GLsizei>(idx.size()), GL_UNSIGNED_INT, idx.data());
    gl.DisableClientState(GL_VERTEX_ARRAY);
    std::vector<uint8_t> rgba(static_cast<std::size_t>(kW) * kH * 4);
    ctx->read_rgba(rgba.data());
    int lit = 0;
    for (std::size_t i = 0; i < rgba.size(); i += 4) lit += rgba[i] != 0 ? 1 : 0;
    return lit;
  };
  EXPECT_EQ(draw(GL_TRIANGLES, dropped_t), 0);
  EXPECT_EQ(draw(GL_LINES, dropped_l), 0);
  EXPECT_GT(draw(GL_TRIANGLES, kept_t), 500);
  EXPECT_GT(draw(GL_LINES, kept_l), 500);
}

}  // namespace
}  // namespace palpate
