#include "render/pixel_cover.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace palpate {

namespace {

// floor and ceil of v after clamping it to [-2, hi + 2]: truncation of a non-negative float, no libm call
// (floorf is one without SSE4.1) and no branch
inline int floor_clamped(float v, float hi) {
  const float c = std::min(std::max(v, -2.0f), hi + 2.0f) + 4.0f;
  const int t = static_cast<int>(c);
  return t - 4;
}
inline int ceil_clamped(float v, float hi) {
  const float c = std::min(std::max(v, -2.0f), hi + 2.0f) + 4.0f;
  const int t = static_cast<int>(c);
  return t - 4 + (static_cast<float>(t) < c ? 1 : 0);
}

}  // namespace

void PixelCover::set(const Eigen::Matrix4d& view_projection, int width, int height) {
  view_projection_ = view_projection;
  width_ = std::clamp(width, 1, 16384);
  height_ = std::clamp(height, 1, 16384);
}

void PixelCover::project(const float* positions, std::size_t n, float* xy) const {
  const double half_w = 0.5 * width_, half_h = 0.5 * height_;
  const Eigen::Matrix4d& m = view_projection_;
  for (std::size_t i = 0; i < n; ++i) {
    const double px = positions[3 * i], py = positions[3 * i + 1], pz = positions[3 * i + 2];
    const double cx = m(0, 0) * px + m(0, 1) * py + m(0, 2) * pz + m(0, 3);
    const double cy = m(1, 0) * px + m(1, 1) * py + m(1, 2) * pz + m(1, 3);
    const double cw = m(3, 0) * px + m(3, 1) * py + m(3, 2) * pz + m(3, 3);
    float x = std::numeric_limits<float>::quiet_NaN(), y = x;
    // GL window coordinates: x right, y up, pixel centres at half integers
    if (cw > 0.0 && std::isfinite(cx) && std::isfinite(cy) && std::isfinite(cw)) {
      x = static_cast<float>((cx / cw + 1.0) * half_w);
      y = static_cast<float>((cy / cw + 1.0) * half_h);
    }
    xy[2 * i] = x;
    xy[2 * i + 1] = y;
  }
}

void PixelCover::cells(const float* xy, std::size_t n, float reach, Cell* out) const {
  const float g = reach + kMarginPx;
  const float w = static_cast<float>(width_), h = static_cast<float>(height_);
  for (std::size_t i = 0; i < n; ++i) {
    const float x = xy[2 * i], y = xy[2 * i + 1];
    if (std::isnan(x) || std::isnan(y)) {
      out[i] = {INT16_MIN, INT16_MAX, INT16_MIN, INT16_MAX};
      continue;
    }
    // centre k + 0.5 within [x - g, x + g]: k from ceil(x - g - 0.5) to floor(x + g - 0.5), in 0 .. w - 1
    out[i].x0 = static_cast<int16_t>(std::max(ceil_clamped(x - g - 0.5f, w), 0));
    out[i].x1 = static_cast<int16_t>(std::min(floor_clamped(x + g - 0.5f, w), width_ - 1));
    out[i].y0 = static_cast<int16_t>(std::max(ceil_clamped(y - g - 0.5f, h), 0));
    out[i].y1 = static_cast<int16_t>(std::min(floor_clamped(y + g - 0.5f, h), height_ - 1));
  }
}

namespace {

// The primitives of `indices` (N per primitive) whose vertices' ranges, taken as a box, hold a pixel centre, appended
// to out. The union of the ranges is [min x0, max x1] x [min y0, max y1]: each vertex's range is clipped to the
// viewport already, and clipping commutes with min and max. The verdict is a coin flip per primitive on a dense
// mesh, so it is combined with & and the indices written always, kept by advancing: no branch on it.
template <int N>
void keep_reaching(const PixelCover::Cell* cells, const uint32_t* indices, std::size_t n_indices,
                   std::vector<uint32_t>* out) {
  const std::size_t start = out->size();
  out->resize(start + n_indices - n_indices % N);
  uint32_t* dst = out->data() + start;
  std::size_t n = 0;
  for (std::size_t k = 0; k + N <= n_indices; k += N) {
    int16_t x0 = INT16_MAX, x1 = INT16_MIN, y0 = INT16_MAX, y1 = INT16_MIN;
    for (int v = 0; v < N; ++v) {
      const PixelCover::Cell& c = cells[indices[k + v]];
      x0 = std::min(x0, c.x0);
      x1 = std::max(x1, c.x1);
      y0 = std::min(y0, c.y0);
      y1 = std::max(y1, c.y1);
      dst[n + v] = indices[k + v];
    }
    n += ((x0 <= x1) & (y0 <= y1)) ? N : 0;
  }
  out->resize(start + n);
}

}  // namespace

void PixelCover::keep_triangles(const Cell* cells, const uint32_t* triangles, std::size_t n_indices,
                                std::vector<uint32_t>* out) {
  keep_reaching<3>(cells, triangles, n_indices, out);
}

void PixelCover::keep_lines(const Cell* cells, const uint32_t* lines, std::size_t n_indices,
                            std::vector<uint32_t>* out) {
  keep_reaching<2>(cells, lines, n_indices, out);
}

}  // namespace palpate
