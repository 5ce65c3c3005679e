#include "render/gl_context.h"


namespace palpate {

namespace {

// The context this thread last bound through make_current(). OSMesa and EGL share Mesa's dispatch, so
// each backend alone can believe its context is still current after the other one was bound.
thread_local const GlContext* t_current = nullptr;

}  // namespace

GlContext::~GlContext() {
  if (t_current == this) t_current = nullptr;
}

bool GlContext::make_current() {
  if (t_current == this) return true;
  if (!bind()) return false;
  t_current = this;
  return true;
}

}  // namespace palpate
