#include "tools/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "render/png_io.h"
#include "tools/plot_font.h"

namespace palpate {
namespace {

using Rgb = std::array<uint8_t, 3>;

class Canvas {
 public:
  Canvas(int w, int h) : w_(w), h_(h), px_(static_cast<std::size_t>(w) * h * 4, 255) {}
  void set(int x, int y, const Rgb& c) {
    if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
    uint8_t* p = &px_[(static_cast<std::size_t>(y) * w_ + x) * 4];
    p[0] = c[0];
    p[1] = c[1];
    p[2] = c[2];
    p[3] = 255;
  }
  void rect(int x0, int y0, int x1, int y1, const Rgb& c) {
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) set(x, y, c);
  }
  // Bresenham line, `thick` pixels wide
  void line(int x0, int y0, int x1, int y1, const Rgb& c, int thick = 1) {
    const int dx = std::abs(x1 - x0), dy = -std::abs(y1 - y0), sx = x0 < x1 ? 1 : -1, sy = y0 < y1 ? 1 : -1;
    int err = dx + dy;
    for (;;) {
      rect(x0 - thick / 2, y0 - thick / 2, x0 + (thick - 1) / 2, y0 + (thick - 1) / 2, c);
      if (x0 == x1 && y0 == y1) break;
      const int e2 = 2 * err;
      if (e2 >= dy) { err += dy; x0 += sx; }
      if (e2 <= dx) { err += dx; y0 += sy; }
    }
  }
  // text at (x, y) top-left, glyphs scaled by s; vertical draws bottom-to-top (rotated left)
  void text(int x, int y, const std::string& s, const Rgb& c, int scale = 2, bool vertical = false) {
    for (std::size_t i = 0; i < s.size(); ++i) {
      const auto g = plot_font::glyph(s[i]);
      for (int r = 0; r < 7; ++r)
        for (int col = 0; col < 5; ++col) {
          if (!(g[r] & (0x10 >> col))) continue;
          const int gx = static_cast<int>(i) * 6 + col, gy = r;
          if (!vertical) rect(x + gx * scale, y + gy * scale, x + gx * scale + scale - 1, y + gy * scale + scale - 1, c);
          else rect(x + gy * scale, y - gx * scale - scale + 1, x + gy * scale + scale - 1, y - gx * scale, c);
        }
    }
  }
  static int text_width(const std::string& s, int scale = 2) { return static_cast<int>(s.size()) * 6 * scale; }
  const uint8_t* data() const { return px_.data(); }

 private:
  int w_, h_;
  std::vector<uint8_t> px_;
};

std::string tick_label(double v, bool log) {
  char buf[32];
  if (log) std::snprintf(buf, sizeof buf, "1e%d", static_cast<int>(std::lround(v)));
  else std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

Status write_plot_png(const PlotSpec& spec, const std::string& path) {
  // data range in axis units (log10 where asked)
  auto ax = [](double v, bool log) { return log ? std::log10(v) : v; };
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const auto& s : spec.series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if ((spec.log_x && !(s.x[i] > 0)) || (spec.log_y && !(s.y[i] > 0)) || !std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, ax(s.x[i], spec.log_x));
      x1 = std::max(x1, ax(s.x[i], spec.log_x));
      y0 = std::min(y0, ax(s.y[i], spec.log_y));
      y1 = std::max(y1, ax(s.y[i], spec.log_y));
    }
  if (!std::isfinite(x0) || !std::isfinite(y0)) return make_error("plot '", path, "': no finite points to plot");
  // whole decades on log axes, 5% padding on linear ones
  auto widen = [](double* lo, double* hi, bool log) {
    if (log) {
      // a little room so points do not sit on the frame
      *lo = std::floor(*lo - 0.05);
      *hi = std::max(std::ceil(*hi + 0.05), *lo + 1.0);
    } else {
      const double pad = std::max(0.05 * (*hi - *lo), 1e-12);
      *lo -= pad;
      *hi += pad;
    }
  };
  widen(&x0, &x1, spec.log_x);
  widen(&y0, &y1, spec.log_y);

  Canvas c(spec.width, spec.height);
  const int left = 110, right = spec.width - 30, top = 50, bottom = spec.height - 70;
  auto px = [&](double v) { return left + static_cast<int>(std::lround((ax(v, spec.log_x) - x0) / (x1 - x0) * (right - left))); };
  auto py = [&](double v) { return bottom - static_cast<int>(std::lround((ax(v, spec.log_y) - y0) / (y1 - y0) * (bottom - top))); };
  const Rgb black{0, 0, 0}, grid{225, 225, 225}, minor{242, 242, 242};
  // grid and ticks
  auto ticks = [](double lo, double hi, bool log) {
    std::vector<double> t;
    const double step = log ? 1.0 : std::pow(10.0, std::floor(std::log10((hi - lo) / 4)));
    for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9; v += step) t.push_back(v);
    return t;
  };
  if (spec.log_x)
    for (double d = x0; d < x1; d += 1.0)
      for (int m = 2; m < 10; ++m) {
        const int x = left + static_cast<int>(std::lround((d + std::log10(m) - x0) / (x1 - x0) * (right - left)));
        c.line(x, top, x, bottom, minor);
      }
  if (spec.log_y)
    for (double d = y0; d < y1; d += 1.0)
      for (int m = 2; m < 10; ++m) {
        const int y = bottom - static_cast<int>(std::lround((d + std::log10(m) - y0) / (y1 - y0) * (bottom - top)));
        c.line(left, y, right, y, minor);
      }
  for (double t : ticks(x0, x1, spec.log_x)) {
    const int x = left + static_cast<int>(std::lround((t - x0) / (x1 - x0) * (right - left)));
    c.line(x, top, x, bottom, grid);
    c.line(x, bottom, x, bottom + 5, black);
    const std::string l = tick_label(t, spec.log_x);
    c.text(x - Canvas::text_width(l) / 2, bottom + 10, l, black);
  }
  for (double t : ticks(y0, y1, spec.log_y)) {
    const int y = bottom - static_cast<int>(std::lround((t - y0) / (y1 - y0) * (bottom - top)));
    c.line(left, y, right, y, grid);
    c.line(left - 5, y, left, y, black);
    const std::string l = tick_label(t, spec.log_y);
    c.text(left - 10 - Canvas::text_width(l), y - 7, l, black);
  }
  c.line(left, top, left, bottom, black, 2);
  c.line(left, bottom, right, bottom, black, 2);
  c.text((left + right - Canvas::text_width(spec.x_label)) / 2, spec.height - 30, spec.x_label, black);
  c.text(20, (top + bottom + Canvas::text_width(spec.y_label)) / 2, spec.y_label, black, 2, true);
  c.text((spec.width - Canvas::text_width(spec.title)) / 2, 15, spec.title, black);
  // data: lines first, markers on top
  auto ok = [&](double x, double y) {
    return std::isfinite(x) && std::isfinite(y) && (!spec.log_x || x > 0) && (!spec.log_y || y > 0);
  };
  for (const auto& s : spec.series) {
    if (!s.line) continue;
    int lx = 0, ly = 0;
    bool have = false;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!ok(s.x[i], s.y[i])) continue;
      const int x = px(s.x[i]), y = py(s.y[i]);
      if (have) c.line(lx, ly, x, y, s.rgb, 2);
      lx = x;
      ly = y;
      have = true;
    }
  }
  for (const auto& s : spec.series) {
    if (!s.points) continue;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
      if (ok(s.x[i], s.y[i])) c.rect(px(s.x[i]) - 4, py(s.y[i]) - 4, px(s.x[i]) + 4, py(s.y[i]) + 4, s.rgb);
  }
  // legend, bottom right (errors fall with cost, so that corner is usually empty)
  int entries = 0;
  for (const auto& s : spec.series) entries += !s.label.empty();
  int ly = bottom - 10 - 22 * entries;
  for (const auto& s : spec.series) {
    if (s.label.empty()) continue;
    const int lx = right - 20 - Canvas::text_width(s.label) - 30;
    if (s.points) c.rect(lx + 6, ly + 3, lx + 14, ly + 11, s.rgb);
    if (s.line) c.line(lx, ly + 7, lx + 20, ly + 7, s.rgb, 2);
    c.text(lx + 28, ly, s.label, black);
    ly += 22;
  }
  return write_png(path, spec.width, spec.height, c.data());
}

}  // namespace palpate
