// The renderer's overlays, drawn over the model each frame: the tool sphere (and its outline where the surface hides
// it), a free tool's drop line and the disc where it lands, the proxy spring and point, the blade.
#include "render/renderer.h"

#include <algorithm>
#include <cmath>

#include "render/renderer_colors.h"

namespace palpate {

using render_colors::kBladeColor;
using render_colors::kDropColor;
using render_colors::kProxyColor;
using render_colors::kShadowColor;
using render_colors::kToolContactColor;
using render_colors::kToolFreeColor;
using render_colors::set_color;

void Renderer::draw_tool(const GlApi& gl, const FrameView& view) const {
  const Vec3& at = view.tool_at_proxy ? view.proxy_pos_m : view.tool_pos_m;
  if (!(view.tool_radius_m > 0.0) || !at.allFinite()) return;
  Eigen::Affine3d model = Eigen::Affine3d::Identity();
  model.translate(at).scale(view.tool_radius_m);
  const Eigen::Matrix4d modelview = view_ * model.matrix();
  gl.LoadMatrixd(modelview.data());
  gl.Enable(GL_LIGHTING);
  set_color(gl, view.in_contact ? kToolContactColor : kToolFreeColor);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.EnableClientState(GL_NORMAL_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, sphere_positions_.data());
  gl.NormalPointer(GL_FLOAT, 0, sphere_positions_.data());
  gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(sphere_indices_.size()), GL_UNSIGNED_INT,
                  sphere_indices_.data());
  // the part of the tool the surface hides, as a wire outline through it (a tool pressed in stays visible)
  gl.Disable(GL_LIGHTING);
  gl.DepthFunc(GL_GREATER);
  gl.PolygonMode(GL_FRONT_AND_BACK, GL_LINE);
  gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(sphere_indices_.size()), GL_UNSIGNED_INT,
                  sphere_indices_.data());
  gl.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  gl.DepthFunc(GL_LEQUAL);
  gl.DisableClientState(GL_NORMAL_ARRAY);
  gl.DisableClientState(GL_VERTEX_ARRAY);
  gl.LoadMatrixd(view_.data());
}

void Renderer::draw_drop(const GlApi& gl, const FrameView& view) const {
  if (!view.show_drop || !view.drop_to_m.allFinite() || !view.tool_pos_m.allFinite() || !view.drop_normal.allFinite())
    return;
  gl.Disable(GL_LIGHTING);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  // a disc on the surface where the line lands, the tool's radius wide (at least 1 mm), lifted off it a little
  constexpr int kSides = 24;
  float disc[3 * (kSides + 2)];
  const Vec3 n = view.drop_normal.normalized();
  const Vec3 u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 v = n.cross(u);
  const double r = std::max(view.tool_radius_m, 1e-3);
  const Vec3 c = view.drop_to_m + n * (0.05 * r);
  for (int i = 0; i <= kSides + 1; ++i) {
    const double a = 2.0 * M_PI * (i - 1) / kSides;
    const Vec3 p = i == 0 ? c : Vec3(c + r * (std::cos(a) * u + std::sin(a) * v));
    for (int k = 0; k < 3; ++k) disc[3 * i + k] = static_cast<float>(p[k]);
  }
  set_color(gl, kShadowColor);
  gl.VertexPointer(3, GL_FLOAT, 0, disc);
  gl.DrawArrays(GL_TRIANGLE_FAN, 0, kSides + 2);
  // the line, drawn over everything like the proxy spring
  const float line[6] = {static_cast<float>(view.tool_pos_m.x()), static_cast<float>(view.tool_pos_m.y()),
                         static_cast<float>(view.tool_pos_m.z()), static_cast<float>(c.x()),
                         static_cast<float>(c.y()),              static_cast<float>(c.z())};
  gl.Disable(GL_DEPTH_TEST);
  set_color(gl, kDropColor);
  gl.VertexPointer(3, GL_FLOAT, 0, line);
  gl.DrawArrays(GL_LINES, 0, 2);
  gl.Enable(GL_DEPTH_TEST);
  gl.DisableClientState(GL_VERTEX_ARRAY);
}

void Renderer::draw_proxy(const GlApi& gl, const FrameView& view) const {
  if (!view.show_proxy || !view.proxy_pos_m.allFinite() || !view.tool_pos_m.allFinite()) return;
  const float line[6] = {static_cast<float>(view.tool_pos_m.x()),  static_cast<float>(view.tool_pos_m.y()),
                         static_cast<float>(view.tool_pos_m.z()),  static_cast<float>(view.proxy_pos_m.x()),
                         static_cast<float>(view.proxy_pos_m.y()), static_cast<float>(view.proxy_pos_m.z())};
  // the spring is an overlay: visible even where the tool has sunk into the surface
  gl.Disable(GL_LIGHTING);
  gl.Disable(GL_DEPTH_TEST);
  set_color(gl, kProxyColor);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, line);
  gl.LineWidth(2.0f);
  gl.DrawArrays(GL_LINES, 0, 2);
  gl.PointSize(7.0f);
  gl.DrawArrays(GL_POINTS, 1, 1);
  gl.DisableClientState(GL_VERTEX_ARRAY);
  gl.LineWidth(1.0f);
  gl.PointSize(1.0f);
  gl.Enable(GL_DEPTH_TEST);
}

void Renderer::draw_blade(const GlApi& gl, const FrameView& view) const {
  if (!view.show_blade || !view.blade_tip_m.allFinite() || !view.blade_end_m.allFinite()) return;
  const float line[6] = {static_cast<float>(view.blade_tip_m.x()), static_cast<float>(view.blade_tip_m.y()),
                         static_cast<float>(view.blade_tip_m.z()), static_cast<float>(view.blade_end_m.x()),
                         static_cast<float>(view.blade_end_m.y()), static_cast<float>(view.blade_end_m.z())};
  // depth-tested: the part inside the object is hidden by its surface, so the blade is seen entering it
  gl.Disable(GL_LIGHTING);
  set_color(gl, kBladeColor);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, line);
  gl.LineWidth(4.0f);
  gl.DrawArrays(GL_LINES, 0, 2);
  gl.DisableClientState(GL_VERTEX_ARRAY);
  gl.LineWidth(1.0f);
}

}  // namespace palpate
