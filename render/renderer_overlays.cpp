// The renderer's overlays, drawn over the model each frame: the tool sphere, the proxy spring and point, the blade.
#include "render/renderer.h"
#include "render/renderer_colors.h"

namespace palpate {

using render_colors::kBladeColor;
using render_colors::kProxyColor;
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
  gl.DisableClientState(GL_NORMAL_ARRAY);
  gl.DisableClientState(GL_VERTEX_ARRAY);
  gl.LoadMatrixd(view_.data());
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
