#pragma once
/// Reading a GL framebuffer into a top-down RGBA8 image.

#include <cstdint>

#include "render/gl_api.h"

namespace palpate {

/// Waits for rendering (glFinish), reads the bound read buffer as RGBA8 into rgba (width*height*4) and flips it
/// so row 0 is the top of the image; does not allocate. Thread: the thread the context is current on.
void read_rgba_top_down(const GlApi& gl, int width, int height, uint8_t* rgba);

}  // namespace palpate
