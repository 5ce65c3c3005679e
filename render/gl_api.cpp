#include "render/gl_api.h"

#include <string>

namespace palpate {

namespace {

// Loads one entry point into *slot; records the first missing name.
template <class F>
void load_one(GlApi::GetProc get_proc, F* slot, const char* name, const char** missing) {
  GlApi::Proc p = get_proc(name);
  *slot = reinterpret_cast<F>(p);
  if (p == nullptr && *missing == nullptr) *missing = name;
}

}  // namespace

Status GlApi::load(GetProc get_proc, const char* backend, const char* loader_name, bool with_fbo) {
  const char* missing = nullptr;
  auto L = [&](auto* slot, const char* name) { load_one(get_proc, slot, name, &missing); };
  L(&Viewport, "glViewport");
  L(&ClearColor, "glClearColor");
  L(&Clear, "glClear");
  L(&Scissor, "glScissor");
  L(&Enable, "glEnable");
  L(&Disable, "glDisable");
  L(&DepthFunc, "glDepthFunc");
  L(&DepthMask, "glDepthMask");
  L(&ShadeModel, "glShadeModel");
  L(&MatrixMode, "glMatrixMode");
  L(&LoadMatrixd, "glLoadMatrixd");
  L(&LoadIdentity, "glLoadIdentity");
  L(&Lightfv, "glLightfv");
  L(&LightModelfv, "glLightModelfv");
  L(&LightModeli, "glLightModeli");
  L(&ColorMaterial, "glColorMaterial");
  L(&Color4f, "glColor4f");
  L(&EnableClientState, "glEnableClientState");
  L(&DisableClientState, "glDisableClientState");
  L(&VertexPointer, "glVertexPointer");
  L(&NormalPointer, "glNormalPointer");
  L(&ColorPointer, "glColorPointer");
  L(&DrawElements, "glDrawElements");
  L(&DrawArrays, "glDrawArrays");
  L(&PolygonMode, "glPolygonMode");
  L(&PolygonOffset, "glPolygonOffset");
  L(&LineWidth, "glLineWidth");
  L(&PointSize, "glPointSize");
  L(&Finish, "glFinish");
  L(&ReadPixels, "glReadPixels");
  L(&PixelStorei, "glPixelStorei");
  L(&ReadBuffer, "glReadBuffer");
  L(&DrawBuffer, "glDrawBuffer");
  L(&GetError, "glGetError");
  L(&GetString, "glGetString");
  L(&GetIntegerv, "glGetIntegerv");
  if (missing != nullptr) {
    return make_error(backend, ": ", loader_name, "('", missing, "') returned null");
  }
  // framebuffer objects: required by the EGL backend, optional elsewhere (the renderer's cached layer uses them)
  L(&GenFramebuffers, "glGenFramebuffers");
  L(&DeleteFramebuffers, "glDeleteFramebuffers");
  L(&BindFramebuffer, "glBindFramebuffer");
  L(&GenRenderbuffers, "glGenRenderbuffers");
  L(&DeleteRenderbuffers, "glDeleteRenderbuffers");
  L(&BindRenderbuffer, "glBindRenderbuffer");
  L(&RenderbufferStorage, "glRenderbufferStorage");
  L(&FramebufferRenderbuffer, "glFramebufferRenderbuffer");
  L(&CheckFramebufferStatus, "glCheckFramebufferStatus");
  L(&BlitFramebuffer, "glBlitFramebuffer");
  has_fbo = missing == nullptr;
  // multisampled renderbuffers (anti-aliased frames) are optional: without them frames are drawn one sample a pixel
  RenderbufferStorageMultisample = reinterpret_cast<PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC>(
      get_proc("glRenderbufferStorageMultisample"));
  if (with_fbo && !has_fbo) {
    return make_error(backend, ": ", loader_name, "('", missing, "') returned null");
  }
  return Ok{};
}

}  // namespace palpate
