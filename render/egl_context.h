#pragma once
/// EglContext: the EGL surfaceless (EGL_PLATFORM_SURFACELESS_MESA) + FBO backend of GlContext.

#include <memory>

#include "render/gl_context.h"

namespace palpate {

/// GlContext on a surfaceless EGL display, drawing into a renderbuffer FBO; not copyable.
/// Thread: create, use and destroy on one thread.
class EglContext final : public GlContext {
 public:
  /// Creates the context and its FBO and makes it current; errors name the EGL/GL call that failed.
  static Result<std::unique_ptr<GlContext>> create(int width, int height);
  ~EglContext() override;

  int width() const override { return width_; }
  int height() const override { return height_; }
  const char* backend_name() const override { return "egl"; }
  const GlApi& gl() const override { return gl_; }
  void read_rgba(uint8_t* rgba) override;

 protected:
  bool bind() override;

 private:
  EglContext(int width, int height) : width_(width), height_(height) {}
  // Creates the FBO with colour and depth renderbuffers; the context must be current.
  Status create_framebuffer();

  int width_ = 0;
  int height_ = 0;
  void* display_ = nullptr;   // EGLDisplay (shared per process, reference-counted)
  void* context_ = nullptr;   // EGLContext
  bool display_ref_ = false;  // holds one reference on the shared display
  unsigned fbo_ = 0;
  unsigned color_rb_ = 0;
  unsigned depth_rb_ = 0;
  GlApi gl_;
};

}  // namespace palpate
