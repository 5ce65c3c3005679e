#pragma once
/// create_gl_context: the one place that knows the GlContext backends (OSMesa, EGL surfaceless) and picks one.

#include <memory>

#include "core/result.h"
#include "core/scene_enums.h"
#include "render/gl_context.h"

namespace palpate {

/// Creates an off-screen context of width x height pixels, current on the calling thread.
/// backend: "osmesa", "egl" (EGL_PLATFORM_SURFACELESS_MESA + an FBO), or "auto" (osmesa first, then egl).
/// Sets LP_NUM_THREADS=0 if unset (GL stays on the calling thread's core). Errors name the backend and the call
/// that failed.
Result<std::unique_ptr<GlContext>> create_gl_context(int width, int height, RenderBackend backend);

}  // namespace palpate
