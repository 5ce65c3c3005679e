#pragma once
/// The part of a cached layer a redraw must touch when only a few triangles move between the static and the moving
/// part: the window rectangle around them, and the static triangles that reach it. Redrawing that rectangle alone
/// (scissored) gives the pixels a whole redraw would: outside it no triangle was added, removed or moved.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/pixel_cover.h"

namespace palpate {

/// A window rectangle in GL pixels: columns x0..x1 - 1, rows y0..y1 - 1 (empty when x1 <= x0 or y1 <= y0).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  /// Pixels covered.
  int64_t area() const { return x1 > x0 && y1 > y0 ? int64_t{x1 - x0} * (y1 - y0) : 0; }
};

/// Grows *rect (clipped to the width x height viewport) to hold the pixels within pad_px of n window positions xy (2
/// floats each). A position that is not finite (behind the eye) makes it the whole viewport.
void grow_rect(const float* xy, std::size_t n, float pad_px, int width, int height, PixelRect* rect);

/// Appends to *out the triangles (index triples into xy's vertices) whose window box reaches the rectangle (a
/// vertex that is not finite reaches everything), in their order.
void triangles_in_rect(const float* xy, const uint32_t* triangles, std::size_t n_indices, const PixelRect& rect,
                       std::vector<uint32_t>* out);

/// The old layer's dynamic part and mesh arrays, kept across a new split to find what changed. Grow-only buffers,
/// copyable. Thread: the render thread.
class LayerPatch {
 public:
  /// Before the split is made anew: the old dynamic part's affected vertices (ascending) and all the vertices it
  /// drew (local), and the first n_vertices positions and normals (3 floats each; normals may be empty) as the
  /// layer was drawn with them.
  void keep(const std::vector<int32_t>& affected, const std::vector<int32_t>& local, const std::vector<float>& positions_f,
            const std::vector<float>& normals_f, std::size_t n_vertices);
  /// After: the rectangle (pad_px around each vertex) holding the old dynamic part's vertices where they are, and
  /// the new one's where they are and, for those the layer drew, where they were. The whole viewport when a vertex
  /// of the old static part moved or turned (its triangles would change outside the rectangle).
  PixelRect rect(const PixelCover& cover, const std::vector<int32_t>& local, const std::vector<float>& positions_f,
                 const std::vector<float>& normals_f, std::size_t n_vertices, float pad_px, int width, int height);

 private:
  // grows *r by the listed vertices of a 3-float array, projected
  void grow_by(const PixelCover& cover, const std::vector<float>& positions_f, float pad_px, int width, int height,
               PixelRect* r);

  std::vector<uint8_t> affected_;     // per old vertex: in the old dynamic part's affected set (n_old)
  std::vector<int32_t> old_local_;    // the old dynamic part's vertices
  std::vector<int32_t> ids_;          // scratch: vertices to place
  std::vector<float> old_positions_f_, old_normals_f_, gathered_f_, xy_;
  std::size_t old_vertices_ = 0;
};

}  // namespace palpate
