// The renderer's overlays, drawn over the model each frame: the tool sphere (and its outline where the surface hides
// it), a free tool's drop line and the disc where it lands, the proxy spring and point, the blade, the force arrow;
// and what is written into the image read back: the legend and the arrow's value.
#include "render/renderer.h"

#include <algorithm>
#include <cmath>

#include "render/annotate.h"

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

void Renderer::fill_disc(const GlApi& gl, const Vec3& c, const Vec3& n, double r) {
  constexpr int kSides = 24;
  float disc[3 * (kSides + 2)];
  const Vec3 u = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  const Vec3 v = n.cross(u);
  for (int i = 0; i <= kSides + 1; ++i) {
    const double a = 2.0 * M_PI * (i - 1) / kSides;
    const Vec3 p = i == 0 ? c : Vec3(c + r * (std::cos(a) * u + std::sin(a) * v));
    for (int k = 0; k < 3; ++k) disc[3 * i + k] = static_cast<float>(p[k]);
  }
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, disc);
  gl.DrawArrays(GL_TRIANGLE_FAN, 0, kSides + 2);
  gl.DisableClientState(GL_VERTEX_ARRAY);
}

void Renderer::draw_drop(const GlApi& gl, const FrameView& view) const {
  if (!view.show_drop || !view.drop_to_m.allFinite() || !view.tool_pos_m.allFinite() || !view.drop_normal.allFinite())
    return;
  gl.Disable(GL_LIGHTING);
  // a disc on the surface where the line lands, the tool's radius wide (at least 1 mm), lifted off it a little
  const Vec3 n = view.drop_normal.normalized();
  const double r = std::max(view.tool_radius_m, 1e-3);
  const Vec3 c = view.drop_to_m + n * (0.05 * r);
  set_color(gl, kShadowColor);
  fill_disc(gl, c, n, r);
  gl.EnableClientState(GL_VERTEX_ARRAY);
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

std::array<uint8_t, 4> Renderer::vertex_color(const FrameView& view, std::size_t v, const Vec3& p) {
  if (view.first_cut_vertex >= 0 && static_cast<int64_t>(v) >= view.first_cut_vertex) return kCutFaceColor;
  if (by_strain(view)) return displacement_color(v < view.vertex_value->size() ? (*view.vertex_value)[v] / view.strain_range : 0.0);
  if (!(view.color_range_m > 0.0) || v >= view.rest_m->size()) return displacement_color(0.0);
  return displacement_color((p - (*view.rest_m)[v]).norm() / view.color_range_m);
}

namespace {

// the force arrow's colour, and how much of the picture's height an arrow of the scale's force spans
constexpr float kArrowColor[4] = {0.90f, 0.43f, 0.0f, 1.0f};
constexpr double kArrowShareOfHeight = 0.2;

}  // namespace

void Renderer::draw_force(const GlApi& gl, const FrameView& view) {
  arrow_drawn_ = false;
  if (!view.show_force || !(view.force_scale_N > 0.0) || !view.force_N.allFinite() || !view.proxy_pos_m.allFinite())
    return;
  // metres per newton so that an arrow of force_scale_N spans kArrowShareOfHeight of the picture at the proxy's depth
  const Vec3 forward = (camera_.target_m - camera_.eye_m).normalized();
  const double depth = (view.proxy_pos_m - camera_.eye_m).dot(forward);
  if (!(depth > 0.0)) return;
  const double view_h_m = 2.0 * depth * std::tan(0.5 * camera_.fov_y_deg * M_PI / 180.0);
  const double m_per_N = kArrowShareOfHeight * view_h_m / view.force_scale_N;
  const double f = view.force_N.norm(), length = f * m_per_N;
  // shorter than a pixel and a half: nothing to see
  if (!(length > 1.5 * view_h_m / ctx_->height())) return;
  const Vec3 dir = view.force_N / f, from = view.proxy_pos_m, tip = from + length * dir;
  const double head = std::min(0.3 * length, 0.25 * kArrowShareOfHeight * view_h_m);
  const Vec3 base = tip - head * dir;
  const Vec3 u = (std::abs(dir.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(dir).normalized(), w = dir.cross(u);
  // drawn over everything, as the proxy spring is: a force pulling into the model stays in sight
  gl.Disable(GL_LIGHTING);
  gl.Disable(GL_DEPTH_TEST);
  set_color(gl, kArrowColor);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  const float shaft[6] = {static_cast<float>(from.x()), static_cast<float>(from.y()), static_cast<float>(from.z()),
                          static_cast<float>(base.x()), static_cast<float>(base.y()), static_cast<float>(base.z())};
  gl.LineWidth(3.0f);
  gl.VertexPointer(3, GL_FLOAT, 0, shaft);
  gl.DrawArrays(GL_LINES, 0, 2);
  gl.LineWidth(1.0f);
  constexpr int kSides = 12;
  float cone[3 * (kSides + 2)];
  for (int i = 0; i <= kSides + 1; ++i) {
    const double a = 2.0 * M_PI * (i - 1) / kSides;
    const Vec3 p = i == 0 ? tip : Vec3(base + 0.4 * head * (std::cos(a) * u + std::sin(a) * w));
    for (int k = 0; k < 3; ++k) cone[3 * i + k] = static_cast<float>(p[k]);
  }
  gl.VertexPointer(3, GL_FLOAT, 0, cone);
  gl.DrawArrays(GL_TRIANGLE_FAN, 0, kSides + 2);
  gl.DisableClientState(GL_VERTEX_ARRAY);
  gl.Enable(GL_DEPTH_TEST);
  arrow_tip_m_ = tip;
  arrow_drawn_ = true;
}

std::vector<uint8_t> Renderer::model_cover(const FrameView& view) const {
  const int gw = cover_w(), gh = cover_h();
  std::vector<uint8_t> cover(static_cast<std::size_t>(gw) * gh, 0);
  if (!view.vertices_m || !view.triangles) return cover;
  const auto& v = *view.vertices_m;
  std::vector<Eigen::Vector2d> at(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) at[i] = project(v[i]) / kCoverCellPx;  // in cells
  auto mark = [&](double x, double y) {
    const int cx = static_cast<int>(std::floor(x)), cy = static_cast<int>(std::floor(y));
    if (cx >= 0 && cy >= 0 && cx < gw && cy < gh) cover[static_cast<std::size_t>(cy * gw + cx)] = 1;
  };
  for (const auto& t : *view.triangles) {
    if (t[0] < 0 || t[1] < 0 || t[2] < 0 || static_cast<std::size_t>(std::max({t[0], t[1], t[2]})) >= v.size()) continue;
    const Eigen::Vector2d &a = at[static_cast<std::size_t>(t[0])], &b = at[static_cast<std::size_t>(t[1])],
                          &c = at[static_cast<std::size_t>(t[2])];
    if (!a.allFinite() || !b.allFinite() || !c.allFinite()) continue;
    for (const Eigen::Vector2d* p : {&a, &b, &c}) mark(p->x(), p->y());
    // the cells whose centre the triangle holds
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int x1 = std::min(gw - 1, static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
    const int y1 = std::min(gh - 1, static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}))));
    auto side = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, double x, double y) {
      return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
    };
    for (int cy = y0; cy <= y1; ++cy)
      for (int cx = x0; cx <= x1; ++cx) {
        const double x = cx + 0.5, y = cy + 0.5;
        const double s0 = side(a, b, x, y), s1 = side(b, c, x, y), s2 = side(c, a, x, y);
        if ((s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0))
          cover[static_cast<std::size_t>(cy * gw + cx)] = 1;
      }
  }
  return cover;
}

void Renderer::annotate(const FrameView& view, uint8_t* rgba) {
  const RgbaImage img{rgba, ctx_->width(), ctx_->height()};
  const int s = text_scale(img.h);
  if (arrow_drawn_) {
    // the arrow's value beside its tip, on a light ground
    const Eigen::Vector2d at = project(arrow_tip_m_);
    if (at.allFinite()) {
      const std::string label = format_force(view.force_N.norm());
      const auto size = text_size(label, s);
      const int x = static_cast<int>(std::lround(at.x())) + 3 * s, y = static_cast<int>(std::lround(at.y())) - size[1] / 2;
      fill_rect(img, x - s, y - s, x + size[0] + s, y + size[1] + s, {255, 255, 255, 190});
      draw_text(img, x, y, label, s, {120, 50, 0, 255});
    }
  }
  const bool trace = view.force_trace != nullptr && view.force_trace_max_N > 0.0;
  std::string title, top;
  if (colored(view) && by_strain(view)) {
    title = "strain";
    top = format_percent(view.strain_range);
  } else if (colored(view) && view.color_range_m > 0.0) {
    title = "displacement";
    top = format_length(view.color_range_m);
  }
  // the arrow's scale (whether or not an arrow is drawn now, so the legend keeps its size): a round force near a
  // quarter of the scale's, and its length in pixels
  double ref_N = 0.0, ref_px = 0.0;
  if (view.force_scale_N > 0.0) {
    ref_N = nice_ceil(0.25 * view.force_scale_N);
    ref_px = kArrowShareOfHeight * img.h * ref_N / view.force_scale_N;
  }
  const bool cut_faces = view.first_cut_vertex >= 0;
  const bool legend = view.show_legend && (!title.empty() || cut_faces || ref_N > 0.0);
  if (!insets_placed_ && (legend || trace) && view.vertices_m != nullptr && !view.vertices_m->empty()) {
    // the insets' corners, once a run (its frames alike): those that cover the least of the model
    insets_placed_ = true;
    const std::vector<uint8_t> cover = model_cover(view);
    auto covered = [&](const std::array<int, 4>& box) {
      int64_t n = 0;
      for (int cy = 0; cy < cover_h(); ++cy)
        for (int cx = 0; cx < cover_w(); ++cx) {
          const int x = cx * kCoverCellPx + kCoverCellPx / 2, y = cy * kCoverCellPx + kCoverCellPx / 2;
          n += cover[static_cast<std::size_t>(cy * cover_w() + cx)] && x >= box[0] && x < box[2] && y >= box[1] &&
               y < box[3];
        }
      return n;
    };
    constexpr Corner kLegendOrder[] = {Corner::kTopRight, Corner::kTopLeft, Corner::kBottomRight, Corner::kBottomLeft};
    constexpr Corner kTraceOrder[] = {Corner::kBottomLeft, Corner::kBottomRight, Corner::kTopLeft, Corner::kTopRight};
    int64_t fewest = -1;
    if (legend)
      for (Corner c : kLegendOrder) {
        const int64_t n = covered(draw_legend(img, title, top, cut_faces, ref_N, ref_px, c, false));
        if (fewest < 0 || n < fewest) fewest = n, legend_corner_ = c;
      }
    fewest = -1;
    if (trace)
      for (Corner c : kTraceOrder) {
        if (legend && c == legend_corner_) continue;
        const int64_t n = covered(draw_force_trace(img, nullptr, 0, view.force_trace_frames, view.force_trace_max_N,
                                                   view.force_trace_s, c, false));
        if (fewest < 0 || n < fewest) fewest = n, trace_corner_ = c;
      }
  }
  if (trace)
    draw_force_trace(img, view.force_trace->data(), view.force_trace->size(), view.force_trace_frames,
                     view.force_trace_max_N, view.force_trace_s, trace_corner_);
  if (legend) draw_legend(img, title, top, cut_faces, ref_N, ref_px, legend_corner_);
}

}  // namespace palpate
