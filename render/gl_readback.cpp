#include "render/gl_readback.h"

#include <algorithm>
#include <cstddef>

namespace palpate {

void read_rgba_top_down(const GlApi& gl, int width, int height, uint8_t* rgba) {
  gl.Finish();
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba);
  // GL rows start at the bottom; swap rows pairwise in place
  const std::size_t row_bytes = static_cast<std::size_t>(width) * 4;
  for (int top = 0, bottom = height - 1; top < bottom; ++top, --bottom) {
    uint8_t* a = rgba + static_cast<std::size_t>(top) * row_bytes;
    uint8_t* b = rgba + static_cast<std::size_t>(bottom) * row_bytes;
    std::swap_ranges(a, a + row_bytes, b);
  }
}

}  // namespace palpate
