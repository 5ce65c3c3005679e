#include "render/gl_context_factory.h"

#include <cstdlib>
#include <string>

#include "render/osmesa_context.h"
#ifdef PALPATE_HAVE_EGL
#include "render/egl_context.h"
#endif

namespace palpate {
namespace {

constexpr int kMaxSizePx = 16384;

Result<std::unique_ptr<GlContext>> create_egl(int width, int height) {
#ifdef PALPATE_HAVE_EGL
  return EglContext::create(width, height);
#else
  (void)width;
  (void)height;
  return make_error("egl: not available (palpate_render was built without EGL)");
#endif
}

}  // namespace

Result<std::unique_ptr<GlContext>> create_gl_context(int width, int height, RenderBackend backend) {
  if (width < 1 || height < 1 || width > kMaxSizePx || height > kMaxSizePx) {
    return make_error("gl context '", name_of(backend), "': size ", std::to_string(width), "x", std::to_string(height),
                      " outside 1..", std::to_string(kMaxSizePx));
  }
  // llvmpipe reads this when its screen is created: 0 keeps rasterisation on the calling thread
  setenv("LP_NUM_THREADS", "0", /*overwrite=*/0);

  switch (backend) {
    case RenderBackend::kOsmesa: return OsMesaContext::create(width, height);
    case RenderBackend::kEgl: return create_egl(width, height);
    case RenderBackend::kAuto: break;
  }
  auto osmesa = OsMesaContext::create(width, height);
  if (osmesa.ok()) return osmesa;
  auto egl = create_egl(width, height);
  if (egl.ok()) return egl;
  return make_error("gl context 'auto': ", osmesa.error().message, "; ", egl.error().message);
}

}  // namespace palpate
