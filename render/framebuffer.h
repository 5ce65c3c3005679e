#pragma once
/// Framebuffer: an RGBA8 + 24-bit depth framebuffer object of one context, and the blit that copies one into
/// another (colour and depth, pixel for pixel).

#include <cstdint>

#include "core/result.h"
#include "render/gl_api.h"

namespace palpate {

/// Owns one framebuffer object and its two renderbuffers; move-only. Create, use and destroy with its context
/// current on the calling thread (the context must outlive it).
class Framebuffer {
 public:
  Framebuffer() = default;
  Framebuffer(Framebuffer&& other) noexcept;
  Framebuffer& operator=(Framebuffer&& other) noexcept;
  Framebuffer(const Framebuffer&) = delete;
  Framebuffer& operator=(const Framebuffer&) = delete;
  ~Framebuffer();

  /// Creates a width x height framebuffer of `samples` samples a pixel (0: one, not multisampled); errors name the
  /// GL status. gl must have has_fbo (and RenderbufferStorageMultisample for samples > 0).
  static Result<Framebuffer> create(const GlApi& gl, int width, int height, int samples = 0);
  /// The GL name of the framebuffer object (0 when empty).
  uint32_t id() const { return fbo_; }
  /// Copies colour and depth of `from` into this framebuffer (same size, formats and samples, so bit-exact).
  void copy_from(const Framebuffer& from) const;
  /// Resolves the colour of a multisampled `from` (same size) into this one-sample framebuffer: each pixel the mean
  /// of its samples.
  void resolve_from(const Framebuffer& from) const;

 private:
  void release();

  const GlApi* gl_ = nullptr;
  int width_ = 0, height_ = 0;
  uint32_t fbo_ = 0, color_rb_ = 0, depth_rb_ = 0;
};

}  // namespace palpate
