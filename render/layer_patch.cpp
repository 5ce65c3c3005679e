#include "render/layer_patch.h"

#include <algorithm>
#include <cmath>

namespace palpate {

void grow_rect(const float* xy, std::size_t n, float pad_px, int width, int height, PixelRect* rect) {
  if (n == 0) return;
  float lo_x = static_cast<float>(rect->x0), lo_y = static_cast<float>(rect->y0);
  float hi_x = static_cast<float>(rect->x1), hi_y = static_cast<float>(rect->y1);
  if (rect->area() == 0) {
    lo_x = lo_y = INFINITY;
    hi_x = hi_y = -INFINITY;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const float x = xy[2 * i], y = xy[2 * i + 1];
    if (!std::isfinite(x) || !std::isfinite(y)) {
      *rect = {0, 0, width, height};
      return;
    }
    lo_x = std::min(lo_x, x - pad_px);
    lo_y = std::min(lo_y, y - pad_px);
    hi_x = std::max(hi_x, x + pad_px);
    hi_y = std::max(hi_y, y + pad_px);
  }
  auto clip = [](float v, int limit) { return static_cast<int>(std::clamp(v, 0.0f, static_cast<float>(limit))); };
  rect->x0 = clip(std::floor(lo_x), width);
  rect->y0 = clip(std::floor(lo_y), height);
  rect->x1 = clip(std::ceil(hi_x), width);
  rect->y1 = clip(std::ceil(hi_y), height);
}

void triangles_in_rect(const float* xy, const uint32_t* triangles, std::size_t n_indices, const PixelRect& rect,
                       std::vector<uint32_t>* out) {
  const auto x0 = static_cast<float>(rect.x0), x1 = static_cast<float>(rect.x1);
  const auto y0 = static_cast<float>(rect.y0), y1 = static_cast<float>(rect.y1);
  for (std::size_t i = 0; i + 2 < n_indices; i += 3) {
    float lo_x = INFINITY, lo_y = INFINITY, hi_x = -INFINITY, hi_y = -INFINITY;
    bool placed = true;
    for (int k = 0; k < 3; ++k) {
      const float x = xy[2 * triangles[i + k]], y = xy[2 * triangles[i + k] + 1];
      placed = placed && std::isfinite(x) && std::isfinite(y);
      lo_x = std::min(lo_x, x);
      lo_y = std::min(lo_y, y);
      hi_x = std::max(hi_x, x);
      hi_y = std::max(hi_y, y);
    }
    if (placed && (hi_x < x0 || lo_x > x1 || hi_y < y0 || lo_y > y1)) continue;
    out->insert(out->end(), {triangles[i], triangles[i + 1], triangles[i + 2]});
  }
}

void LayerPatch::keep(const std::vector<int32_t>& affected, const std::vector<int32_t>& local,
                      const std::vector<float>& positions_f, const std::vector<float>& normals_f, std::size_t n_vertices) {
  old_vertices_ = n_vertices;
  affected_.assign(n_vertices, 0);
  for (int32_t v : affected) affected_[static_cast<std::size_t>(v)] = 1;
  old_local_ = local;
  old_positions_f_.assign(positions_f.begin(), positions_f.begin() + static_cast<std::ptrdiff_t>(3 * n_vertices));
  const std::size_t n_normals = normals_f.size() >= 3 * n_vertices ? 3 * n_vertices : 0;
  old_normals_f_.assign(normals_f.begin(), normals_f.begin() + static_cast<std::ptrdiff_t>(n_normals));
}

void LayerPatch::grow_by(const PixelCover& cover, const std::vector<float>& positions_f, float pad_px, int width,
                         int height, PixelRect* r) {
  gathered_f_.clear();
  for (int32_t v : ids_) gathered_f_.insert(gathered_f_.end(), &positions_f[3 * v], &positions_f[3 * v] + 3);
  xy_.resize(2 * ids_.size());
  cover.project(gathered_f_.data(), ids_.size(), xy_.data());
  grow_rect(xy_.data(), ids_.size(), pad_px, width, height, r);
}

PixelRect LayerPatch::rect(const PixelCover& cover, const std::vector<int32_t>& local,
                           const std::vector<float>& positions_f, const std::vector<float>& normals_f,
                           std::size_t n_vertices, float pad_px, int width, int height) {
  const PixelRect whole{0, 0, width, height};
  if (n_vertices < old_vertices_ || positions_f.size() < 3 * n_vertices) return whole;
  // a vertex of the old static part that moved or turned changes triangles the rectangle may not hold
  const bool normals = !old_normals_f_.empty() && normals_f.size() >= 3 * old_vertices_;
  for (std::size_t v = 0; v < old_vertices_; ++v) {
    if (affected_[v]) continue;
    const std::size_t i = 3 * v;
    if (!std::equal(&old_positions_f_[i], &old_positions_f_[i] + 3, &positions_f[i])) return whole;
    if (normals && !std::equal(&old_normals_f_[i], &old_normals_f_[i] + 3, &normals_f[i])) return whole;
  }
  PixelRect r;
  // the triangles leaving the layer: their vertices where the layer drew them (those of its static part)
  ids_.clear();
  for (int32_t v : local)
    if (static_cast<std::size_t>(v) < old_vertices_ && !affected_[static_cast<std::size_t>(v)]) ids_.push_back(v);
  grow_by(cover, old_positions_f_, pad_px, width, height, &r);
  // the triangles joining it and those leaving it, where they are now
  ids_ = old_local_;
  ids_.insert(ids_.end(), local.begin(), local.end());
  grow_by(cover, positions_f, pad_px, width, height, &r);
  return r;
}

}  // namespace palpate
