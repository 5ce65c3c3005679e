#include "render/osmesa_context.h"

#include <GL/osmesa.h>

#include "render/gl_readback.h"

namespace palpate {

Result<std::unique_ptr<GlContext>> OsMesaContext::create(int width, int height) {
  std::unique_ptr<OsMesaContext> ctx(new OsMesaContext(width, height));
  ctx->context_ = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
  if (ctx->context_ == nullptr) {
    return make_error("osmesa: OSMesaCreateContextExt(OSMESA_RGBA, depth 24) failed");
  }
  ctx->buffer_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4, 0);
  if (!ctx->make_current()) {
    return make_error("osmesa: OSMesaMakeCurrent(", std::to_string(width), "x", std::to_string(height),
                      ") failed");
  }
  Status loaded = ctx->gl_.load(&OSMesaGetProcAddress, "osmesa", "OSMesaGetProcAddress", /*with_fbo=*/false);
  if (!loaded.ok()) return loaded.error();
  return std::unique_ptr<GlContext>(std::move(ctx));
}

OsMesaContext::~OsMesaContext() {
  if (context_ == nullptr) return;
  auto* handle = static_cast<OSMesaContext>(context_);
  if (OSMesaGetCurrentContext() == handle) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
  OSMesaDestroyContext(handle);
}

bool OsMesaContext::bind() {
  return OSMesaMakeCurrent(static_cast<OSMesaContext>(context_), buffer_.data(), GL_UNSIGNED_BYTE, width_,
                           height_) == GL_TRUE;
}

void OsMesaContext::read_rgba(uint8_t* rgba) { read_rgba_top_down(gl_, width_, height_, rgba); }

}  // namespace palpate
