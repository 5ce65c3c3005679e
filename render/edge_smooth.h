#pragma once
/// EdgeSmoother: anti-aliased edges from the image alone, at a cost that follows what changed between frames.
///
/// Multisampling on llvmpipe costs the whole frame again and more (the bunny subdivided four times, the rest of the frame
/// the same: render p50 14.6-14.9 ms at 2 or 4 samples against 6.6 ms at one), whatever the number of samples. This pass works on the image read
/// back instead, the way image-space anti-aliasing (FXAA, MLAA) does: where the luma contrast around a pixel marks
/// an edge, it finds the edge's direction and how far the pixel lies from the ends of the step it belongs to, and
/// blends it with its neighbour across the edge by the share of the pixel the smooth edge would cover. A staircase
/// of a slanted edge becomes a ramp of coverage; a pixel-sized feature is softened by the contrast it makes with its
/// 3 x 3 neighbourhood.
///
/// A frame's output depends only on input pixels within kReach of it, so after the first frame only the rectangle
/// where the input changed since the last frame, grown by kReach, is worked on; the rest is the last output's.
/// Grow-only buffers of two images (the last input and output); not thread-safe.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace palpate {

class EdgeSmoother {
 public:
  /// Pixels an output pixel's value can depend on, in any direction (the edge-end search and its neighbours).
  static constexpr int kSearchSteps = 10;
  static constexpr int kReach = kSearchSteps + 2;

  /// Smooths the edges of rgba (w x h, 4 bytes a pixel, any row order) in place. A size other than the last
  /// call's works on the whole image.
  void apply(uint8_t* rgba, int w, int h);
  /// Forgets the last frame: the next apply() works on the whole image.
  void reset() { width_ = height_ = 0; }
  /// Pixels the last apply() worked on (the whole image on a first frame or a new size).
  int64_t last_worked_px() const { return last_worked_px_; }

 private:
  // smooths the rectangle [x0, x1) x [y0, y1) of in_ into rgba, reading in_ and luma_ around it
  void smooth_rect(uint8_t* rgba, int x0, int y0, int x1, int y1) const;

  int width_ = 0, height_ = 0;
  std::vector<uint8_t> in_;   // the last input (w * h * 4)
  std::vector<uint8_t> out_;  // the last output
  std::vector<float> luma_;   // the input's luma, 0-1 (w * h)
  int64_t last_worked_px_ = 0;
};

}  // namespace palpate
