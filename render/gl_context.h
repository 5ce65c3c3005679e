#pragma once
/// GlContext: an off-screen OpenGL context (OSMesa or EGL surfaceless) behind one interface.

#include <cstdint>
#include <memory>
#include <string>

#include "core/result.h"
#include "core/scene_enums.h"
#include "render/gl_api.h"

namespace palpate {

/// An off-screen GL context with its own colour + depth buffer of a fixed size; not copyable, not movable.
/// Thread: create, use and destroy on one thread.
class GlContext {
 public:
  GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;
  virtual ~GlContext();

  /// Framebuffer width in pixels.
  virtual int width() const = 0;
  /// Framebuffer height in pixels.
  virtual int height() const = 0;
  /// "osmesa" or "egl".
  virtual const char* backend_name() const = 0;
  /// Makes this context current on the calling thread (a no-op when it already is); false on failure.
  /// Switching between OSMesa and EGL contexts on one thread is supported.
  bool make_current();
  /// The GL entry points of this context (valid while the context lives and is current).
  virtual const GlApi& gl() const = 0;
  /// Reads the current framebuffer as RGBA8, rows top-down (row 0 = top of image), into rgba (w*h*4).
  virtual void read_rgba(uint8_t* rgba) = 0;

 protected:
  /// Binds the context to the calling thread, even if the backend believes it already is bound.
  virtual bool bind() = 0;
};


}  // namespace palpate
