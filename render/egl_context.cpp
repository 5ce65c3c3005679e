#include "render/egl_context.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <cstring>
#include <mutex>

#include "render/gl_readback.h"

namespace palpate {

namespace {

// The surfaceless display is one per process: initialise on first use, terminate with the last context.
std::mutex g_display_mutex;
int g_display_refs = 0;

// "EGL_BAD_ALLOC (0x3003)" for the last EGL error on this thread.
std::string egl_error_text() {
  const EGLint code = eglGetError();
  const char* name = "unknown";
  switch (code) {
    case EGL_SUCCESS: name = "EGL_SUCCESS"; break;
    case EGL_NOT_INITIALIZED: name = "EGL_NOT_INITIALIZED"; break;
    case EGL_BAD_ACCESS: name = "EGL_BAD_ACCESS"; break;
    case EGL_BAD_ALLOC: name = "EGL_BAD_ALLOC"; break;
    case EGL_BAD_ATTRIBUTE: name = "EGL_BAD_ATTRIBUTE"; break;
    case EGL_BAD_CONFIG: name = "EGL_BAD_CONFIG"; break;
    case EGL_BAD_CONTEXT: name = "EGL_BAD_CONTEXT"; break;
    case EGL_BAD_DISPLAY: name = "EGL_BAD_DISPLAY"; break;
    case EGL_BAD_MATCH: name = "EGL_BAD_MATCH"; break;
    case EGL_BAD_PARAMETER: name = "EGL_BAD_PARAMETER"; break;
    case EGL_BAD_SURFACE: name = "EGL_BAD_SURFACE"; break;
    default: break;
  }
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%04x", static_cast<unsigned>(code));
  return std::string(name) + " (" + hex + ")";
}

// True when the space-separated extension list holds exactly `name`.
bool has_extension(const char* list, const char* name) {
  if (list == nullptr) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = std::strstr(list, name); p != nullptr; p = std::strstr(p + 1, name)) {
    const bool starts = p == list || p[-1] == ' ';
    const bool ends = p[n] == '\0' || p[n] == ' ';
    if (starts && ends) return true;
  }
  return false;
}

}  // namespace

Result<std::unique_ptr<GlContext>> EglContext::create(int width, int height) {
  std::unique_ptr<EglContext> ctx(new EglContext(width, height));

  // client extensions: the surfaceless platform must be there
  const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (client_ext == nullptr) {
    return make_error("egl: eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS) failed: ", egl_error_text());
  }
  if (!has_extension(client_ext, "EGL_MESA_platform_surfaceless")) {
    return make_error("egl: client extension EGL_MESA_platform_surfaceless not available");
  }
  auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) {
    return make_error("egl: eglGetProcAddress('eglGetPlatformDisplayEXT') returned null");
  }
  EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) {
    return make_error("egl: eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA) failed: ", egl_error_text());
  }
  ctx->display_ = display;
  {
    std::lock_guard<std::mutex> lock(g_display_mutex);
    if (g_display_refs == 0) {
      EGLint major = 0, minor = 0;
      if (eglInitialize(display, &major, &minor) != EGL_TRUE) {
        return make_error("egl: eglInitialize(surfaceless display) failed: ", egl_error_text());
      }
    }
    ++g_display_refs;
    ctx->display_ref_ = true;
  }

  const char* display_ext = eglQueryString(display, EGL_EXTENSIONS);
  if (!has_extension(display_ext, "EGL_KHR_surfaceless_context")) {
    return make_error("egl: display extension EGL_KHR_surfaceless_context not available");
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    return make_error("egl: eglBindAPI(EGL_OPENGL_API) failed: ", egl_error_text());
  }

  // a config is only a formality without surfaces; fall back to no config where allowed
  const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                   EGL_NONE};
  EGLConfig config = nullptr;
  EGLint num_configs = 0;
  if (eglChooseConfig(display, config_attribs, &config, 1, &num_configs) != EGL_TRUE || num_configs < 1) {
    if (!has_extension(display_ext, "EGL_KHR_no_config_context")) {
      return make_error("egl: eglChooseConfig(EGL_OPENGL_BIT) found no config: ", egl_error_text());
    }
    config = EGL_NO_CONFIG_KHR;
  }
  const EGLint context_attribs[] = {EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT, EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
  if (context == EGL_NO_CONTEXT) {
    return make_error("egl: eglCreateContext(OpenGL compatibility profile) failed: ", egl_error_text());
  }
  ctx->context_ = context;
  if (!ctx->make_current()) {
    return make_error("egl: eglMakeCurrent(EGL_NO_SURFACE) failed: ", egl_error_text());
  }

  Status loaded = ctx->gl_.load(&eglGetProcAddress, "egl", "eglGetProcAddress", /*with_fbo=*/true);
  if (!loaded.ok()) return loaded.error();
  Status fbo = ctx->create_framebuffer();
  if (!fbo.ok()) return fbo.error();
  return std::unique_ptr<GlContext>(std::move(ctx));
}

Status EglContext::create_framebuffer() {
  const GlApi& gl = gl_;
  gl.GenFramebuffers(1, &fbo_);
  gl.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
  gl.GenRenderbuffers(1, &color_rb_);
  gl.BindRenderbuffer(GL_RENDERBUFFER, color_rb_);
  gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width_, height_);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rb_);
  gl.GenRenderbuffers(1, &depth_rb_);
  gl.BindRenderbuffer(GL_RENDERBUFFER, depth_rb_);
  gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width_, height_);
  gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_rb_);
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%04x", status);
    return make_error("egl: glCheckFramebufferStatus(", std::to_string(width_), "x", std::to_string(height_),
                      " RGBA8 + DEPTH24) returned ", hex, " (not complete)");
  }
  gl.DrawBuffer(GL_COLOR_ATTACHMENT0);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  const GLenum error = gl.GetError();
  if (error != GL_NO_ERROR) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%04x", error);
    return make_error("egl: framebuffer setup raised GL error ", hex);
  }
  return Ok{};
}

EglContext::~EglContext() {
  auto display = static_cast<EGLDisplay>(display_);
  if (context_ != nullptr) {
    auto context = static_cast<EGLContext>(context_);
    // GL objects can only be deleted with their context current
    if ((fbo_ != 0 || color_rb_ != 0 || depth_rb_ != 0) && make_current()) {
      gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
      if (fbo_ != 0) gl_.DeleteFramebuffers(1, &fbo_);
      if (color_rb_ != 0) gl_.DeleteRenderbuffers(1, &color_rb_);
      if (depth_rb_ != 0) gl_.DeleteRenderbuffers(1, &depth_rb_);
    }
    if (eglGetCurrentContext() == context) {
      eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglDestroyContext(display, context);
  }
  if (display_ref_) {
    std::lock_guard<std::mutex> lock(g_display_mutex);
    if (--g_display_refs == 0) {
      eglTerminate(display);
      eglReleaseThread();
    }
  }
}

bool EglContext::bind() {
  auto display = static_cast<EGLDisplay>(display_);
  auto context = static_cast<EGLContext>(context_);
  // Mesa skips a bind to the context it thinks is current, though OSMesa may have taken the dispatch since
  if (eglGetCurrentContext() == context) eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  const bool ok = eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) == EGL_TRUE;
  if (ok && fbo_ != 0) gl_.BindFramebuffer(GL_FRAMEBUFFER, fbo_);
  return ok;
}

void EglContext::read_rgba(uint8_t* rgba) { read_rgba_top_down(gl_, width_, height_, rgba); }

}  // namespace palpate
