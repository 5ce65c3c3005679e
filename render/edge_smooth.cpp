#include "render/edge_smooth.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace palpate {

namespace {

// a contrast below this (luma 0-1), or below this share of the brightest luma around, is not an edge
constexpr float kEdgeMin = 0.0312f;
constexpr float kEdgeShare = 0.125f;
// how much of a pixel-sized feature's contrast with its neighbourhood is blended away (0: none, 1: all)
constexpr float kSubpixel = 0.75f;

float luma_of(const uint8_t* p) { return (0.299f * p[0] + 0.587f * p[1] + 0.114f * p[2]) * (1.0f / 255.0f); }

// the first and one past the last pixel of a row where a and b differ; false when they are equal
bool row_diff(const uint8_t* a, const uint8_t* b, int w, int* first, int* last) {
  const std::size_t bytes = static_cast<std::size_t>(w) * 4;
  if (std::memcmp(a, b, bytes) == 0) return false;
  const auto* pa = reinterpret_cast<const unsigned char*>(a);
  const auto* pb = reinterpret_cast<const unsigned char*>(b);
  int f = 0;
  while (std::memcmp(pa + 4 * f, pb + 4 * f, 4) == 0) ++f;
  int l = w - 1;
  while (std::memcmp(pa + 4 * l, pb + 4 * l, 4) == 0) --l;
  *first = f;
  *last = l + 1;
  return true;
}

}  // namespace

void EdgeSmoother::apply(uint8_t* rgba, int w, int h) {
  if (w <= 0 || h <= 0 || rgba == nullptr) return;
  const std::size_t row = static_cast<std::size_t>(w) * 4;
  const std::size_t bytes = row * static_cast<std::size_t>(h);
  int x0 = 0, y0 = 0, x1 = w, y1 = h;  // the changed rectangle
  if (w != width_ || h != height_) {
    width_ = w;
    height_ = h;
    in_.assign(rgba, rgba + bytes);
    out_.resize(bytes);
    luma_.resize(static_cast<std::size_t>(w) * h);
  } else {
    x0 = w, y0 = h, x1 = 0, y1 = 0;
    for (int y = 0; y < h; ++y) {
      int f = 0, l = 0;
      if (!row_diff(rgba + y * row, in_.data() + y * row, w, &f, &l)) continue;
      x0 = std::min(x0, f), x1 = std::max(x1, l);
      y0 = std::min(y0, y), y1 = y + 1;
    }
    if (x0 >= x1) {  // nothing changed: the last output
      std::memcpy(rgba, out_.data(), bytes);
      last_worked_px_ = 0;
      return;
    }
    for (int y = y0; y < y1; ++y)
      std::memcpy(in_.data() + y * row + 4 * x0, rgba + y * row + 4 * x0, 4 * static_cast<std::size_t>(x1 - x0));
  }
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      luma_[static_cast<std::size_t>(y) * w + x] = luma_of(in_.data() + y * row + 4 * x);
  const bool whole = x0 == 0 && y0 == 0 && x1 == w && y1 == h;
  if (!whole) {
    // every pixel whose output can change: within kReach of a changed one
    x0 = std::max(0, x0 - kReach), y0 = std::max(0, y0 - kReach);
    x1 = std::min(w, x1 + kReach), y1 = std::min(h, y1 + kReach);
    std::memcpy(rgba, out_.data(), bytes);
  }
  smooth_rect(rgba, x0, y0, x1, y1);
  for (int y = y0; y < y1; ++y)
    std::memcpy(out_.data() + y * row + 4 * x0, rgba + y * row + 4 * x0, 4 * static_cast<std::size_t>(x1 - x0));
  last_worked_px_ = static_cast<int64_t>(x1 - x0) * (y1 - y0);
}

void EdgeSmoother::smooth_rect(uint8_t* rgba, int x0, int y0, int x1, int y1) const {
  const int w = width_, h = height_;
  const std::size_t row = static_cast<std::size_t>(w) * 4;
  // luma at (x, y), clamped to the image
  auto L = [&](int x, int y) {
    x = std::clamp(x, 0, w - 1);
    y = std::clamp(y, 0, h - 1);
    return luma_[static_cast<std::size_t>(y) * w + x];
  };
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const uint8_t* c = in_.data() + y * row + 4 * x;
      uint8_t* o = rgba + y * row + 4 * x;
      const float m = L(x, y), n = L(x, y - 1), s = L(x, y + 1), wl = L(x - 1, y), e = L(x + 1, y);
      const float hi = std::max({m, n, s, wl, e}), lo = std::min({m, n, s, wl, e});
      const float range = hi - lo;
      if (range < std::max(kEdgeMin, hi * kEdgeShare)) {
        std::memcpy(o, c, 4);
        continue;
      }
      const float nw = L(x - 1, y - 1), ne = L(x + 1, y - 1), sw = L(x - 1, y + 1), se = L(x + 1, y + 1);
      // an edge along x changes luma along y (and the other way round)
      const float along_x = std::abs(nw + sw - 2 * wl) + 2 * std::abs(n + s - 2 * m) + std::abs(ne + se - 2 * e);
      const float along_y = std::abs(nw + ne - 2 * n) + 2 * std::abs(wl + e - 2 * m) + std::abs(sw + se - 2 * s);
      const bool horizontal = along_x >= along_y;
      // across the edge: toward the neighbour with the larger step
      const float l_neg = horizontal ? n : wl, l_pos = horizontal ? s : e;
      const float g_neg = std::abs(l_neg - m), g_pos = std::abs(l_pos - m);
      const int dir = g_neg >= g_pos ? -1 : 1;
      const float g_scaled = 0.25f * std::max(g_neg, g_pos);
      const float local_avg = 0.5f * (m + (dir < 0 ? l_neg : l_pos));
      // along the edge, each way, to where the pair of pixels astride it no longer averages to the edge's luma
      const int ax = horizontal ? 1 : 0, ay = horizontal ? 0 : 1;  // along
      const int cx = horizontal ? 0 : dir, cy = horizontal ? dir : 0;  // across
      auto end_of = [&](int sign, float* end_luma) {
        int i = 1;
        for (; i <= kSearchSteps; ++i) {
          const int px = x + sign * i * ax, py = y + sign * i * ay;
          *end_luma = 0.5f * (L(px, py) + L(px + cx, py + cy)) - local_avg;
          if (std::abs(*end_luma) >= g_scaled) break;
        }
        return static_cast<float>(std::min(i, kSearchSteps));
      };
      float end_neg = 0.0f, end_pos = 0.0f;
      const float d_neg = end_of(-1, &end_neg), d_pos = end_of(1, &end_pos);
      const bool neg_closer = d_neg < d_pos;
      const float closer_end = neg_closer ? end_neg : end_pos;
      // the pixel is blended only on the side of the step where the edge passes over it
      float blend = 0.0f;
      if ((closer_end < 0.0f) != (m < local_avg)) blend = 0.5f - std::min(d_neg, d_pos) / (d_neg + d_pos);
      // a pixel-sized feature: by its contrast with the average of its 3 x 3 neighbourhood
      const float avg = (2.0f * (n + s + wl + e) + nw + ne + sw + se) * (1.0f / 12.0f);
      const float sub1 = std::clamp(std::abs(avg - m) / range, 0.0f, 1.0f);
      const float sub2 = (-2.0f * sub1 + 3.0f) * sub1 * sub1;
      blend = std::max(blend, sub2 * sub2 * kSubpixel);
      const int nx = std::clamp(x + cx, 0, w - 1), ny = std::clamp(y + cy, 0, h - 1);
      const uint8_t* d = in_.data() + ny * row + 4 * nx;
      for (int k = 0; k < 3; ++k) o[k] = static_cast<uint8_t>(std::lround(c[k] + blend * (d[k] - c[k])));
      o[3] = c[3];
    }
  }
}

}  // namespace palpate
