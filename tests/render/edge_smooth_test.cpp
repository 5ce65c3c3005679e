// Edges smoothed in the image: a slanted edge drawn one sample a pixel comes out closer to the share of each pixel
// the true edge covers (an analytic reference, measured by fine supersampling of the half-plane), flat and faint
// images are left alone, and working only where the input changed gives the pixels of working on the whole image.
#include "render/edge_smooth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

namespace palpate {
namespace {

constexpr int kW = 96;
constexpr int kH = 72;

// the share of pixel (x, y) below the line y = y0 + slope (x - x0) (pixel centres at +0.5), by 32 x 32 samples
double covered(int x, int y, double slope, double x0, double y0) {
  int in = 0;
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j) {
      const double px = x + (i + 0.5) / 32.0, py = y + (j + 0.5) / 32.0;
      in += py > y0 + slope * (px - x0);
    }
  return in / 1024.0;
}

// a dark half-plane on white below a slanted line, drawn as a rasteriser does: a pixel is dark when its centre is in
std::vector<uint8_t> aliased_edge(double slope, double x0, double y0) {
  std::vector<uint8_t> img(static_cast<std::size_t>(kW) * kH * 4);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool dark = y + 0.5 > y0 + slope * (x + 0.5 - x0);
      uint8_t* p = &img[(static_cast<std::size_t>(y) * kW + x) * 4];
      p[0] = p[1] = p[2] = dark ? 40 : 240;
      p[3] = 255;
    }
  return img;
}

// mean |coverage read from the image - the true coverage| over pixels the line passes through or beside
double coverage_error(const std::vector<uint8_t>& img, double slope, double x0, double y0) {
  double sum = 0.0;
  int n = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 8; x < kW - 8; ++x) {
      const double truth = covered(x, y, slope, x0, y0);
      const double line_y = y0 + slope * (x + 0.5 - x0);
      if (std::abs(y + 0.5 - line_y) > 2.0) continue;
      const double read = (240.0 - img[(static_cast<std::size_t>(y) * kW + x) * 4]) / 200.0;
      sum += std::abs(read - truth);
      ++n;
    }
  return n > 0 ? sum / n : 0.0;
}

TEST(EdgeSmooth, ASlantedEdgeComesOutCloserToTheShareOfEachPixelItCovers) {
  // shallow and steep slopes, both ways (an edge along x and one along y)
  for (double slope : {0.13, 0.31, -0.42, 2.7, -6.0}) {
    const double x0 = 0.5 * kW, y0 = 0.5 * kH + 0.3;
    std::vector<uint8_t> img = aliased_edge(slope, x0, y0);
    const double before = coverage_error(img, slope, x0, y0);
    EdgeSmoother smoother;
    smoother.apply(img.data(), kW, kH);
    const double after = coverage_error(img, slope, x0, y0);
    EXPECT_GT(before, 0.05) << "slope " << slope;
    EXPECT_LT(after, 0.45 * before) << "slope " << slope << ": " << before << " -> " << after;
    EXPECT_EQ(smoother.last_worked_px(), kW * kH);
  }
}

TEST(EdgeSmooth, FlatAndFaintImagesAreLeftAlone) {
  std::vector<uint8_t> img(static_cast<std::size_t>(kW) * kH * 4);
  for (std::size_t i = 0; i < img.size(); ++i) img[i] = static_cast<uint8_t>(i % 4 == 3 ? 255 : 120 + (i / 4 % kW) % 5);
  const std::vector<uint8_t> before = img;
  EdgeSmoother smoother;
  smoother.apply(img.data(), kW, kH);
  EXPECT_EQ(img, before);  // a luma step of 5/255 is under the edge threshold
}

TEST(EdgeSmooth, WorkingWhereTheInputChangedGivesThePixelsOfTheWholeImage) {
  std::mt19937 rng(7);
  std::vector<uint8_t> img = aliased_edge(0.27, 40.0, 30.0);
  EdgeSmoother incremental;
  for (int frame = 0; frame < 12; ++frame) {
    // a small dark square moves about; now and then a second edge changes far away
    const int sx = static_cast<int>(rng() % (kW - 10)), sy = static_cast<int>(rng() % (kH - 10));
    std::vector<uint8_t> in = frame % 4 == 3 ? aliased_edge(0.27 + 0.05 * frame, 40.0, 30.0) : img;
    for (int y = sy; y < sy + 6; ++y)
      for (int x = sx; x < sx + 7; ++x) {
        uint8_t* p = &in[(static_cast<std::size_t>(y) * kW + x) * 4];
        p[0] = 10, p[1] = 200, p[2] = 90;
      }
    std::vector<uint8_t> a = in, b = in;
    incremental.apply(a.data(), kW, kH);
    EdgeSmoother fresh;
    fresh.apply(b.data(), kW, kH);
    ASSERT_EQ(a, b) << "frame " << frame;
    if (frame > 0 && frame % 4 != 3 && (frame - 1) % 4 != 3) {
      EXPECT_LT(incremental.last_worked_px(), kW * kH) << "frame " << frame;
    }
  }
  // the same input again: nothing to work on, the same output
  std::vector<uint8_t> again = img, once = img;
  EdgeSmoother s;
  s.apply(once.data(), kW, kH);
  s.apply(again.data(), kW, kH);
  EXPECT_EQ(s.last_worked_px(), 0);
  EXPECT_EQ(again, once);
}

}  // namespace
}  // namespace palpate
