// What the annotations write into an image without GL: the legend's numbers rounded and read in their unit, the colour
// map's ends, and the force trace's inset drawn into a plain RGBA buffer.
#include "render/annotate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace palpate {
namespace {

TEST(Annotate, RangesRoundUpToOneTwoOrFiveAndNumbersReadInTheirUnit) {
  EXPECT_DOUBLE_EQ(nice_ceil(0.009006), 0.01);
  EXPECT_DOUBLE_EQ(nice_ceil(0.0031), 0.005);
  EXPECT_DOUBLE_EQ(nice_ceil(0.125), 0.2);
  EXPECT_DOUBLE_EQ(nice_ceil(0.002), 0.002);
  EXPECT_EQ(nice_ceil(0.0), 0.0);
  EXPECT_EQ(nice_ceil(NAN), 0.0);
  EXPECT_EQ(format_length(0.01), "10 mm");
  EXPECT_EQ(format_length(0.0015), "1.5 mm");
  EXPECT_EQ(format_length(0.00025), "250 um");
  EXPECT_EQ(format_length(0.2), "200 mm");
  EXPECT_EQ(format_length(0.0), "0");
  EXPECT_EQ(format_force(0.4213), "0.42 N");
  EXPECT_EQ(format_force(-3.3), "3.3 N");
  EXPECT_EQ(format_force(12.4), "12 N");
  // the map: the model's own colour at 0, dark red at the top, clamped beyond, NaN as 0
  EXPECT_EQ(displacement_color(0.0), (Rgba8{168, 186, 214, 255}));
  EXPECT_EQ(displacement_color(1.0), (Rgba8{176, 26, 30, 255}));
  EXPECT_EQ(displacement_color(7.0), displacement_color(1.0));
  EXPECT_EQ(displacement_color(NAN), displacement_color(0.0));
}

// The force trace's inset: a steady force is a flat line at its share of the scale, a rising one rises to the right
// (the newest value at the right edge), and values past the scale stay inside the plot.
TEST(Annotate, TheForceTraceDrawsEachFramesForceAtItsShareOfTheScaleNewestAtTheRight) {
  constexpr int w = 640, h = 480;
  std::vector<uint8_t> px(static_cast<std::size_t>(w) * h * 4, 0);
  const RgbaImage img{px.data(), w, h};
  auto line_rows = [&](int* x_lo, int* x_hi, std::vector<std::pair<int, int>>* points) {
    *x_lo = w, *x_hi = -1;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const uint8_t* p = &px[(static_cast<std::size_t>(y) * w + x) * 4];
        if (p[0] == 230 && p[1] == 110 && p[2] == 0) {
          *x_lo = std::min(*x_lo, x), *x_hi = std::max(*x_hi, x);
          points->push_back({x, y});
        }
      }
  };
  // steady at half the scale over the whole span
  const std::vector<float> steady(120, 1.65f);
  const auto box = draw_force_trace(img, steady.data(), steady.size(), 120, 3.3, 2.0);
  int x_lo = 0, x_hi = 0;
  std::vector<std::pair<int, int>> pts;
  line_rows(&x_lo, &x_hi, &pts);
  ASSERT_FALSE(pts.empty());
  int y_min = h, y_max = 0;
  for (auto [x, y] : pts) y_min = std::min(y_min, y), y_max = std::max(y_max, y);
  EXPECT_EQ(y_min, y_max) << "a steady force is one row";
  // in the bottom-left inset, about half way up its plot
  EXPECT_LT(box[2], w / 2);
  EXPECT_GT(box[1], h / 2);
  const int plot_h = std::max(30, h / 7), plot_bottom = box[3] - 4 * text_scale(h) - 1;
  EXPECT_NEAR(plot_bottom - y_min, 0.5 * (plot_h - 1), 1.0);
  // rising from 0 to twice the scale over the last half of the span: the line starts half way across, climbs, and
  // is held at the plot's top past the scale
  std::fill(px.begin(), px.end(), 0);
  std::vector<float> rising(60);
  for (std::size_t i = 0; i < rising.size(); ++i) rising[i] = static_cast<float>(6.6 * i / (rising.size() - 1));
  draw_force_trace(img, rising.data(), rising.size(), 120, 3.3, 2.0);
  pts.clear();
  line_rows(&x_lo, &x_hi, &pts);
  ASSERT_FALSE(pts.empty());
  const int plot_w = std::max(60, w * 3 / 10);
  EXPECT_NEAR(x_hi - x_lo, 0.5 * plot_w, 3.0);
  int y_at_lo = 0, y_at_hi = h;
  for (auto [x, y] : pts) {
    if (x == x_lo) y_at_lo = std::max(y_at_lo, y);
    if (x == x_hi) y_at_hi = std::min(y_at_hi, y);
  }
  EXPECT_EQ(y_at_lo, plot_bottom);
  EXPECT_EQ(y_at_hi, plot_bottom - (plot_h - 1));
}

}  // namespace
}  // namespace palpate
