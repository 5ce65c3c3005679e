#pragma once
/// The renderer's colours (RGBA): the model, its wireframe, and the overlays — the tool blue while free and red in
/// contact, the proxy spring and point green, the blade near-black. Private to render/.

#include "render/gl_context.h"

namespace palpate::render_colors {

inline constexpr float kBackground[4] = {0.97f, 0.97f, 0.98f, 1.0f};
inline constexpr float kMeshColor[4] = {0.66f, 0.73f, 0.84f, 1.0f};
inline constexpr float kWireColor[4] = {0.16f, 0.18f, 0.24f, 1.0f};
inline constexpr float kToolFreeColor[4] = {0.15f, 0.45f, 0.85f, 1.0f};
inline constexpr float kToolContactColor[4] = {0.90f, 0.10f, 0.08f, 1.0f};
inline constexpr float kProxyColor[4] = {0.10f, 0.55f, 0.22f, 1.0f};
inline constexpr float kDropColor[4] = {0.25f, 0.25f, 0.28f, 1.0f};    ///< a free tool's drop line
inline constexpr float kShadowColor[4] = {0.08f, 0.08f, 0.10f, 1.0f};  ///< the disc where it meets the surface
inline constexpr float kBladeColor[4] = {0.08f, 0.08f, 0.10f, 1.0f};

/// Sets the current colour for the fixed-function draws that follow.
inline void set_color(const GlApi& gl, const float* c) { gl.Color4f(c[0], c[1], c[2], c[3]); }

}  // namespace palpate::render_colors
