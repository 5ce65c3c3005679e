#pragma once
/// PixelCover: which triangles and lines can reach a pixel centre of the viewport. GL rasterises a triangle
/// only at the pixel centres inside it and a 1-pixel line only at centres within half a pixel of it, so a
/// primitive whose window bounding box (grown by that reach and a rounding margin) holds no centre writes no
/// fragment: leaving it out of a draw changes no pixel. On meshes denser than the image most triangles are
/// smaller than a pixel and most of them fall between the centres.

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace palpate {

/// One camera and viewport; plain data, copyable. Thread: any.
class PixelCover {
 public:
  /// Margin, in pixels, by which a bounding box is grown beyond the rasteriser's reach: covers the rounding of
  /// a double projection against GL's float pipeline and llvmpipe's 1/256-pixel vertex snapping.
  static constexpr float kMarginPx = 1.0f / 32.0f;
  /// How far from a 1-pixel line a fragment's centre can lie along either axis (half the diamond of the
  /// diamond-exit rule; half the width of the 1-pixel quad llvmpipe draws).
  static constexpr float kLineReachPx = 0.5f;

  /// The pixel-centre columns x0..x1 and rows y0..y1 (viewport-clipped, empty when x0 > x1 or y0 > y1) within
  /// a reach of one vertex; a primitive reaches a centre when the union of its vertices' ranges, taken as a box,
  /// is not empty. A vertex that cannot be placed (behind the eye, not finite) reaches every centre.
  struct Cell {
    int16_t x0, x1, y0, y1;
  };

  /// view_projection: world -> clip (projection * view, column-major); the viewport is width x height pixels
  /// (at most 16384 each).
  void set(const Eigen::Matrix4d& view_projection, int width, int height);

  /// Window positions of n vertices (3 floats each, world frame) into xy (2 floats each): x, y in pixels, GL
  /// window coordinates. A vertex on or behind the eye plane, or not finite, gets NaN.
  void project(const float* positions, std::size_t n, float* xy) const;
  /// The cells of n window positions for primitives that reach `reach` pixels beyond their vertices' box
  /// (0 for triangles, kLineReachPx for lines; kMarginPx is added).
  void cells(const float* xy, std::size_t n, float reach, Cell* out) const;

  /// Appends to out the triangles (index triples into cells) that may cover a pixel centre.
  static void keep_triangles(const Cell* cells, const uint32_t* triangles, std::size_t n_indices,
                             std::vector<uint32_t>* out);
  /// Appends to out the lines (index pairs into cells) that may reach a pixel centre.
  static void keep_lines(const Cell* cells, const uint32_t* lines, std::size_t n_indices, std::vector<uint32_t>* out);

 private:
  Eigen::Matrix4d view_projection_ = Eigen::Matrix4d::Identity();
  int width_ = 1, height_ = 1;
};

}  // namespace palpate
