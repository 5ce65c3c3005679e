#include "render/annotate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace palpate {
namespace {

// a glyph: 7 rows of 5 bits, the leftmost column the highest bit
struct Glyph {
  char c;
  std::array<uint8_t, 7> rows;
};

constexpr Glyph kFont[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}}, {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}}, {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}}, {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}}, {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}}, {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}}, {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}}, {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}}, {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}},
    {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}}, {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}}, {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}}, {'|', {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'N', {0x11, 0x19, 0x15, 0x13, 0x11, 0x11, 0x11}}, {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
    {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}}, {'a', {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}},
    {'b', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x1E}}, {'c', {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}},
    {'d', {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F}}, {'e', {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
    {'f', {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}}, {'g', {0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E}},
    {'h', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}}, {'i', {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}},
    {'k', {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}}, {'l', {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'m', {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11}}, {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'o', {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}}, {'p', {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10}},
    {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}}, {'s', {0x00, 0x00, 0x0E, 0x10, 0x0E, 0x01, 0x1E}},
    {'t', {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}}, {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D}},
    {'v', {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04}}, {'w', {0x00, 0x00, 0x11, 0x11, 0x15, 0x15, 0x0A}},
    {'x', {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}}, {'y', {0x00, 0x00, 0x11, 0x11, 0x0F, 0x01, 0x0E}},
};

const Glyph* glyph(char c) {
  for (const Glyph& g : kFont)
    if (g.c == c) return &g;
  return nullptr;
}

void blend(uint8_t* p, Rgba8 c) {
  if (c[3] == 255) {
    p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
    return;
  }
  const int a = c[3];
  for (int k = 0; k < 3; ++k) p[k] = static_cast<uint8_t>((c[k] * a + p[k] * (255 - a) + 127) / 255);
  p[3] = 255;
}

// two significant figures, trailing zeros dropped ("1.5", "12", "250", "0.42")
std::string two_figures(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2g", x);
  // %.2g writes 120 as "1.2e+02"
  if (std::string(b).find('e') != std::string::npos) std::snprintf(b, sizeof b, "%.0f", x);
  return b;
}

}  // namespace

namespace {

// the map at u in [0, 1], exactly: stops at the mesh's blue-grey, a pale yellow, orange, dark red
Rgba8 map_exact(double u) {
  static constexpr double kStops[4][3] = {{168, 186, 214}, {246, 226, 122}, {242, 140, 52}, {176, 26, 30}};
  u = std::clamp(u, 0.0, 1.0) * 3.0;
  const int i = std::min(2, static_cast<int>(u));
  const double f = u - i;
  Rgba8 c{0, 0, 0, 255};
  for (int k = 0; k < 3; ++k)
    c[static_cast<std::size_t>(k)] = static_cast<uint8_t>(std::lround(kStops[i][k] + f * (kStops[i + 1][k] - kStops[i][k])));
  return c;
}

// the map tabulated: a frame colours every moving vertex, and a step of 1/1023 moves a channel by under a third
constexpr int kMapSteps = 1023;

}  // namespace

Rgba8 displacement_color(double u) {
  static const std::array<Rgba8, kMapSteps + 1> table = [] {
    std::array<Rgba8, kMapSteps + 1> t{};
    for (int i = 0; i <= kMapSteps; ++i) t[static_cast<std::size_t>(i)] = map_exact(static_cast<double>(i) / kMapSteps);
    return t;
  }();
  if (!(u > 0.0)) return table[0];  // and NaN
  return table[u >= 1.0 ? kMapSteps : static_cast<std::size_t>(u * kMapSteps + 0.5)];
}

double nice_ceil(double x) {
  if (!(x > 0.0) || !std::isfinite(x)) return 0.0;
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= x * (1.0 - 1e-12)) return m * p;
  return 10.0 * p;
}

std::string format_length(double m) {
  if (!(m > 0.0)) return "0";
  if (m < 1e-3) return two_figures(m * 1e6) + " um";
  if (m < 1.0) return two_figures(m * 1e3) + " mm";
  return two_figures(m) + " m";
}

std::string format_percent(double fraction) {
  return fraction > 0.0 ? two_figures(100.0 * fraction) + " %" : std::string("0");
}

std::string format_force(double n) { return two_figures(std::abs(n)) + " N"; }

int text_scale(int h) { return std::max(1, h / 240); }

std::array<int, 2> text_size(std::string_view text, int scale) {
  const int n = static_cast<int>(text.size());
  return {n > 0 ? (6 * n - 1) * scale : 0, 7 * scale};
}

void draw_text(RgbaImage img, int x, int y, std::string_view text, int scale, Rgba8 color) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const Glyph* g = glyph(text[i]);
    if (!g) continue;
    const int gx = x + static_cast<int>(i) * 6 * scale;
    for (int r = 0; r < 7; ++r)
      for (int col = 0; col < 5; ++col)
        if (g->rows[static_cast<std::size_t>(r)] & (0x10 >> col))
          fill_rect(img, gx + col * scale, y + r * scale, gx + (col + 1) * scale, y + (r + 1) * scale, color);
  }
}

void fill_rect(RgbaImage img, int x0, int y0, int x1, int y1, Rgba8 color) {
  x0 = std::max(x0, 0), y0 = std::max(y0, 0), x1 = std::min(x1, img.w), y1 = std::min(y1, img.h);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) blend(img.px + (static_cast<std::size_t>(y) * img.w + x) * 4, color);
}

std::array<int, 4> draw_legend(RgbaImage img, const std::string& title, const std::string& top, bool cut_faces,
                               double force_ref_N, double force_ref_px, Corner corner, bool draw) {
  const int s = text_scale(img.h);
  const Rgba8 ink{40, 44, 56, 255}, paper{255, 255, 255, 200};
  const int pad = 4 * s, bar_w = 6 * s, bar_h = std::max(40, img.h / 4), line = 10 * s;
  const bool bar = !title.empty(), arrow = force_ref_N > 0.0;
  const std::string ref = arrow ? format_force(force_ref_N) : std::string();
  const int arrow_px = static_cast<int>(std::lround(force_ref_px));
  int inner_w = 0, inner_h = 0;
  if (bar) {
    inner_w = std::max(text_size(title, s)[0], bar_w + 2 * s + std::max(text_size(top, s)[0], text_size("0", s)[0]));
    inner_h += line + bar_h + 3 * s;
  }
  if (cut_faces) {
    inner_w = std::max(inner_w, bar_w + 2 * s + text_size("cut", s)[0]);
    inner_h += line;
  }
  if (arrow) {
    inner_w = std::max(inner_w, arrow_px + 2 * s + text_size(ref, s)[0]);
    inner_h += line;
  }
  const auto [x0, y0, x1, y1] = corner_box(img.w, img.h, inner_w + 2 * pad, inner_h + 2 * pad - 3 * s, pad, corner);
  if (!draw) return {x0, y0, x1, y1};
  fill_rect(img, x0, y0, x1, y1, paper);
  const int x = x0 + pad;
  int y = y0 + pad;
  if (bar) {
    draw_text(img, x, y, title, s, ink);
    y += line;
    // the map from 0 at the bottom to the range at the top, both ends labelled
    const int bar_y0 = y, bar_y1 = y + bar_h;
    for (int r = bar_y0; r < bar_y1; ++r)
      fill_rect(img, x, r, x + bar_w, r + 1, displacement_color(static_cast<double>(bar_y1 - 1 - r) / (bar_h - 1)));
    draw_text(img, x + bar_w + 2 * s, bar_y0, top, s, ink);
    draw_text(img, x + bar_w + 2 * s, bar_y1 - 7 * s, "0", s, ink);
    y = bar_y1 + 3 * s;
  }
  if (cut_faces) {
    fill_rect(img, x, y, x + bar_w, y + 7 * s, kCutFaceColor);
    draw_text(img, x + bar_w + 2 * s, y, "cut", s, ink);
    y += line;
  }
  if (arrow) {
    // the arrow's scale: a bar as long as the arrow of force_ref_N, with its head
    const Rgba8 orange{230, 110, 0, 255};
    fill_rect(img, x, y + 3 * s, x + arrow_px, y + 4 * s + 1, orange);
    fill_rect(img, x + arrow_px - s, y + s, x + arrow_px + 1, y + 6 * s + 1, orange);
    draw_text(img, x + arrow_px + 3 * s, y, ref, s, ink);
  }
  return {x0, y0, x1, y1};
}

std::array<int, 4> corner_box(int img_w, int img_h, int w, int h, int pad, Corner corner) {
  const bool right = corner == Corner::kTopRight || corner == Corner::kBottomRight;
  const bool top = corner == Corner::kTopRight || corner == Corner::kTopLeft;
  const int x0 = right ? img_w - pad - w : pad, y0 = top ? pad : img_h - pad - h;
  return {x0, y0, x0 + w, y0 + h};
}

std::array<int, 4> draw_force_trace(RgbaImage img, const float* values, std::size_t n, std::size_t capacity,
                                    double scale_N, double span_s, Corner corner, bool draw) {
  const int s = text_scale(img.h);
  const Rgba8 ink{40, 44, 56, 255}, paper{255, 255, 255, 200}, grid{200, 202, 210, 255}, line{230, 110, 0, 255};
  const int pad = 4 * s, w = std::max(60, img.w * 3 / 10), h = std::max(30, img.h / 7);
  const auto [x0, y0, x1, y1] = corner_box(img.w, img.h, w + 2 * pad, h + 2 * pad + 10 * s, pad, corner);
  if (!draw) return {x0, y0, x1, y1};
  fill_rect(img, x0, y0, x1, y1, paper);
  // the plot: time across (span_s at the full width, now at the right), force up from 0 to scale_N
  const int px0 = x0 + pad, px1 = px0 + w, py1 = y1 - pad, py0 = py1 - h;
  fill_rect(img, px0, py0, px1, py0 + 1, grid);
  fill_rect(img, px0, py1 - 1, px1, py1, grid);
  draw_text(img, px0, y0 + pad, "|F| to " + format_force(scale_N) + ", " + two_figures(span_s) + " s", s, ink);
  if (n == 0 || capacity < 2 || !(scale_N > 0.0)) return {x0, y0, x1, y1};
  auto row = [&](float v) {
    const double u = std::clamp(std::isfinite(v) ? static_cast<double>(v) / scale_N : 0.0, 0.0, 1.0);
    return py1 - 1 - static_cast<int>(std::lround(u * (h - 1)));
  };
  // the newest value at the right edge, each joined to the one before by a column span
  const std::size_t first = n > capacity ? n - capacity : 0;
  int prev_x = -1, prev_y = 0;
  for (std::size_t i = first; i < n; ++i) {
    const auto age = static_cast<double>(n - 1 - i);
    const int x = px1 - 1 - static_cast<int>(std::lround(age * (w - 1) / static_cast<double>(capacity - 1)));
    const int y = row(values[i]);
    const int lo = prev_x < 0 ? y : std::min(y, prev_y), hi = prev_x < 0 ? y : std::max(y, prev_y);
    fill_rect(img, prev_x < 0 ? x : prev_x + 1, lo, x + 1, hi + 1, line);
    fill_rect(img, x, lo, x + 1, hi + 1, line);
    prev_x = x;
    prev_y = y;
  }
  return {x0, y0, x1, y1};
}

}  // namespace palpate
