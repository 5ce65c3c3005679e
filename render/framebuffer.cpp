#include "render/framebuffer.h"

#include <cstdio>
#include <string>
#include <utility>

namespace palpate {

Framebuffer::Framebuffer(Framebuffer&& other) noexcept { *this = std::move(other); }

Framebuffer& Framebuffer::operator=(Framebuffer&& other) noexcept {
  if (this != &other) {
    release();
    gl_ = std::exchange(other.gl_, nullptr);
    width_ = other.width_;
    height_ = other.height_;
    fbo_ = std::exchange(other.fbo_, 0u);
    color_rb_ = std::exchange(other.color_rb_, 0u);
    depth_rb_ = std::exchange(other.depth_rb_, 0u);
  }
  return *this;
}

Framebuffer::~Framebuffer() { release(); }

void Framebuffer::release() {
  if (gl_ == nullptr) return;
  if (fbo_ != 0) gl_->DeleteFramebuffers(1, &fbo_);
  if (color_rb_ != 0) gl_->DeleteRenderbuffers(1, &color_rb_);
  if (depth_rb_ != 0) gl_->DeleteRenderbuffers(1, &depth_rb_);
  fbo_ = color_rb_ = depth_rb_ = 0;
  gl_ = nullptr;
}

Result<Framebuffer> Framebuffer::create(const GlApi& gl, int width, int height, int samples) {
  if (!gl.has_fbo) return make_error("framebuffer: the context has no framebuffer objects");
  if (samples > 0 && gl.RenderbufferStorageMultisample == nullptr)
    return make_error("framebuffer: the context has no multisampled renderbuffers");
  auto storage = [&](GLenum format) {
    if (samples > 0) gl.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, width, height);
    else gl.RenderbufferStorage(GL_RENDERBUFFER, format, width, height);
  };
  GLint previous = 0;
  gl.GetIntegerv(GL_FRAMEBUFFER_BINDING, &previous);
  Framebuffer f;
  f.gl_ = &gl;
  f.width_ = width;
  f.height_ = height;
  gl.GenFramebuffers(1, &f.fbo_);
  gl.BindFramebuffer(GL_FRAMEBUFFER, f.fbo_);
  gl.GenRenderbuffers(1, &f.color_rb_);
  gl.BindRenderbuffer(GL_RENDERBUFFER, f.color_rb_);
  storage(GL_RGBA8);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, f.color_rb_);
  gl.GenRenderbuffers(1, &f.depth_rb_);
  gl.BindRenderbuffer(GL_RENDERBUFFER, f.depth_rb_);
  storage(GL_DEPTH_COMPONENT24);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, f.depth_rb_);
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  gl.BindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(previous));
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%04x", status);
    return make_error("framebuffer: glCheckFramebufferStatus(", std::to_string(width), "x", std::to_string(height),
                      " RGBA8 + DEPTH24, ", std::to_string(samples), " samples) returned ", hex, " (not complete)");
  }
  return f;
}

void Framebuffer::copy_from(const Framebuffer& from) const {
  gl_->BindFramebuffer(GL_READ_FRAMEBUFFER, from.fbo_);
  gl_->BindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_);
  gl_->BlitFramebuffer(0, 0, from.width_, from.height_, 0, 0, width_, height_,
                       GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT, GL_NEAREST);
  gl_->BindFramebuffer(GL_FRAMEBUFFER, fbo_);
}

void Framebuffer::resolve_from(const Framebuffer& from) const {
  gl_->BindFramebuffer(GL_READ_FRAMEBUFFER, from.fbo_);
  gl_->BindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_);
  gl_->BlitFramebuffer(0, 0, from.width_, from.height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  gl_->BindFramebuffer(GL_FRAMEBUFFER, fbo_);
}

}  // namespace palpate
