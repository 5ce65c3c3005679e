#pragma once
/// GlApi: the OpenGL entry points the renderer uses, loaded from one context's get-proc-address.

#include <GL/gl.h>
#include <GL/glext.h>

#include "core/result.h"

namespace palpate {

/// A function-pointer table for one GL context; plain data, copyable.
/// Loading through the backend (OSMesaGetProcAddress / eglGetProcAddress) keeps the renderer free of
/// link-order clashes between libOSMesa and libGL, so both backends can live in one process.
struct GlApi {
  /// Any GL entry point, as returned by the backend's get-proc-address.
  using Proc = void (*)();
  /// The backend's get-proc-address function.
  using GetProc = Proc (*)(const char* name);

  // fixed-function state and drawing (GL 1.1)
  decltype(&::glViewport) Viewport = nullptr;
  decltype(&::glClearColor) ClearColor = nullptr;
  decltype(&::glClear) Clear = nullptr;
  decltype(&::glScissor) Scissor = nullptr;
  decltype(&::glEnable) Enable = nullptr;
  decltype(&::glDisable) Disable = nullptr;
  decltype(&::glDepthFunc) DepthFunc = nullptr;
  decltype(&::glDepthMask) DepthMask = nullptr;
  decltype(&::glShadeModel) ShadeModel = nullptr;
  decltype(&::glMatrixMode) MatrixMode = nullptr;
  decltype(&::glLoadMatrixd) LoadMatrixd = nullptr;
  decltype(&::glLoadIdentity) LoadIdentity = nullptr;
  decltype(&::glLightfv) Lightfv = nullptr;
  decltype(&::glLightModelfv) LightModelfv = nullptr;
  decltype(&::glLightModeli) LightModeli = nullptr;
  decltype(&::glColorMaterial) ColorMaterial = nullptr;
  decltype(&::glColor4f) Color4f = nullptr;
  decltype(&::glEnableClientState) EnableClientState = nullptr;
  decltype(&::glDisableClientState) DisableClientState = nullptr;
  decltype(&::glVertexPointer) VertexPointer = nullptr;
  decltype(&::glNormalPointer) NormalPointer = nullptr;
  decltype(&::glColorPointer) ColorPointer = nullptr;
  decltype(&::glDrawElements) DrawElements = nullptr;
  decltype(&::glDrawArrays) DrawArrays = nullptr;
  decltype(&::glPolygonMode) PolygonMode = nullptr;
  decltype(&::glPolygonOffset) PolygonOffset = nullptr;
  decltype(&::glLineWidth) LineWidth = nullptr;
  decltype(&::glPointSize) PointSize = nullptr;
  decltype(&::glFinish) Finish = nullptr;
  decltype(&::glReadPixels) ReadPixels = nullptr;
  decltype(&::glPixelStorei) PixelStorei = nullptr;
  decltype(&::glReadBuffer) ReadBuffer = nullptr;
  decltype(&::glDrawBuffer) DrawBuffer = nullptr;
  decltype(&::glGetError) GetError = nullptr;
  decltype(&::glGetString) GetString = nullptr;
  decltype(&::glGetIntegerv) GetIntegerv = nullptr;

  // framebuffer objects (GL 3.0); loaded only when asked for
  PFNGLGENFRAMEBUFFERSPROC GenFramebuffers = nullptr;
  PFNGLDELETEFRAMEBUFFERSPROC DeleteFramebuffers = nullptr;
  PFNGLBINDFRAMEBUFFERPROC BindFramebuffer = nullptr;
  PFNGLGENRENDERBUFFERSPROC GenRenderbuffers = nullptr;
  PFNGLDELETERENDERBUFFERSPROC DeleteRenderbuffers = nullptr;
  PFNGLBINDRENDERBUFFERPROC BindRenderbuffer = nullptr;
  PFNGLRENDERBUFFERSTORAGEPROC RenderbufferStorage = nullptr;
  PFNGLFRAMEBUFFERRENDERBUFFERPROC FramebufferRenderbuffer = nullptr;
  PFNGLCHECKFRAMEBUFFERSTATUSPROC CheckFramebufferStatus = nullptr;
  PFNGLBLITFRAMEBUFFERPROC BlitFramebuffer = nullptr;
  PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC RenderbufferStorageMultisample = nullptr;  ///< may be null (no multisampling)
  bool has_fbo = false;  ///< every framebuffer-object entry point above is loaded

  /// Fills the table through get_proc; fails naming the backend, the loader and the first missing entry point.
  /// with_fbo: the framebuffer-object entry points are required too (else they are loaded when present).
  Status load(GetProc get_proc, const char* backend, const char* loader_name, bool with_fbo);
};

}  // namespace palpate
