// What the renderer's layered path hands GL: the triangles and lines that reach a pixel centre (PixelCover), from
// the window positions and cells of their vertices.
#include "render/renderer.h"

namespace palpate {

void Renderer::place(const float* positions, std::size_t n, std::vector<float>* xy,
                     std::vector<PixelCover::Cell>* fill_cells, std::vector<PixelCover::Cell>* line_cells) const {
  cover_.project(positions, n, xy->data());
  if (fill_drawn()) {
    if (fill_cells->size() < xy->size() / 2) fill_cells->resize(xy->size() / 2);
    cover_.cells(xy->data(), n, 0.0f, fill_cells->data());
  }
  if (lines_drawn()) {
    if (line_cells->size() < xy->size() / 2) line_cells->resize(xy->size() / 2);
    cover_.cells(xy->data(), n, PixelCover::kLineReachPx, line_cells->data());
  }
}

const uint32_t* Renderer::covering_triangles(bool cull, const PixelCover::Cell* cells, const uint32_t* tris,
                                             std::size_t count, std::size_t* kept) {
  last_drawn_.triangles = count / 3;
  if (!fill_drawn()) {
    *kept = 0;
  } else if (!cull) {
    *kept = count;
  } else {
    kept_triangles_.clear();
    PixelCover::keep_triangles(cells, tris, count, &kept_triangles_);
    *kept = kept_triangles_.size();
    tris = kept_triangles_.data();
  }
  last_drawn_.triangles_drawn = *kept / 3;
  return tris;
}

const std::vector<uint32_t>& Renderer::covering_lines(bool cull, const PixelCover::Cell* cells,
                                                      const std::vector<uint32_t>& lines) {
  last_drawn_.lines = lines.size() / 2;
  const std::vector<uint32_t>* out = &lines;
  if (!lines_drawn()) {
    kept_lines_.clear();
    out = &kept_lines_;
  } else if (cull) {
    kept_lines_.clear();
    PixelCover::keep_lines(cells, lines.data(), lines.size(), &kept_lines_);
    out = &kept_lines_;
  }
  last_drawn_.lines_drawn = out->size() / 2;
  return *out;
}

}  // namespace palpate
