// The renderer's floor: a square with a faint grid under the model, and the shadows the model and the tool cast on it
// from a light above (kShadowLight): the model's triangles flattened onto the floor, their corners snapped to a
// two-pixel grid there, drawn in one flat colour without writing depth, so whatever is nearer the eye covers them.
#include "render/renderer.h"

#include <algorithm>
#include <cmath>

#include "render/renderer_colors.h"

namespace palpate {

using render_colors::set_color;

namespace {

constexpr float kFloorColor[4] = {0.89f, 0.90f, 0.92f, 1.0f};
constexpr float kFloorLineColor[4] = {0.82f, 0.83f, 0.86f, 1.0f};
constexpr float kFloorShadowColor[4] = {0.66f, 0.67f, 0.71f, 1.0f};
constexpr float kToolShadowColor[4] = {0.42f, 0.43f, 0.47f, 1.0f};
constexpr int kFloorLines = 10;  // grid lines across the floor each way (a scale for the eye)

}  // namespace

Vec3 Renderer::on_floor(const FrameView& view, const Vec3& p) {
  // along the light to the plane z = floor_z_m (a point below it goes up to it: the light is never under the floor)
  const double t = (p.z() - view.floor_z_m) / -kShadowLight.z();
  return Vec3(p.x() + t * kShadowLight.x(), p.y() + t * kShadowLight.y(), view.floor_z_m);
}

Vec3 Renderer::shadow_point(const FrameView& view, const Vec3& p) const {
  Vec3 f = on_floor(view, p);
  if (shadow_grid_m_ > 0.0 && f.allFinite())
    for (int k = 0; k < 2; ++k) f[k] = shadow_grid_m_ * std::round(f[k] / shadow_grid_m_);
  return f;
}

void Renderer::draw_floor(const GlApi& gl, const FrameView& view) const {
  // seen from below the floor it would hide nothing it should: not drawn (its shadows neither)
  if (!(camera_.eye_m.z() > view.floor_z_m)) return;
  const double z = view.floor_z_m, h = view.floor_half_m;
  const Vec3& c = view.floor_centre_m;
  gl.Disable(GL_LIGHTING);
  gl.DepthMask(GL_FALSE);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  const float quad[12] = {static_cast<float>(c.x() - h), static_cast<float>(c.y() - h), static_cast<float>(z),
                          static_cast<float>(c.x() + h), static_cast<float>(c.y() - h), static_cast<float>(z),
                          static_cast<float>(c.x() + h), static_cast<float>(c.y() + h), static_cast<float>(z),
                          static_cast<float>(c.x() - h), static_cast<float>(c.y() + h), static_cast<float>(z)};
  set_color(gl, kFloorColor);
  gl.VertexPointer(3, GL_FLOAT, 0, quad);
  gl.DrawArrays(GL_TRIANGLE_FAN, 0, 4);
  float lines[2 * (kFloorLines + 1) * 6];
  int n = 0;
  for (int i = 0; i <= kFloorLines; ++i) {
    const auto a = static_cast<float>(-h + 2.0 * h * i / kFloorLines);
    const float x0 = static_cast<float>(c.x()), y0 = static_cast<float>(c.y()), hh = static_cast<float>(h);
    const float zz = static_cast<float>(z);
    const float seg[12] = {x0 + a, y0 - hh, zz, x0 + a, y0 + hh, zz, x0 - hh, y0 + a, zz, x0 + hh, y0 + a, zz};
    for (float v : seg) lines[n++] = v;
  }
  set_color(gl, kFloorLineColor);
  gl.VertexPointer(3, GL_FLOAT, 0, lines);
  gl.DrawArrays(GL_LINES, 0, n / 3);
  gl.DisableClientState(GL_VERTEX_ARRAY);
  gl.DepthMask(GL_TRUE);
}

void Renderer::draw_shadow(const GlApi& gl, const float* flat, const void* indices, std::size_t count) const {
  if (count == 0 || !(camera_.eye_m.z() > floor_z_)) return;
  // one flat colour, no depth written: the model drawn after covers it where it is nearer the eye, and shadows
  // that overlap look as one
  gl.Disable(GL_LIGHTING);
  gl.DepthMask(GL_FALSE);
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, flat);
  set_color(gl, kFloorShadowColor);
  gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT, indices);
  gl.DisableClientState(GL_VERTEX_ARRAY);
  gl.DepthMask(GL_TRUE);
}

void Renderer::draw_tool_shadow(const GlApi& gl, const FrameView& view) const {
  const Vec3& at = view.tool_at_proxy ? view.proxy_pos_m : view.tool_pos_m;
  if (!floor_shown(view) || !(view.tool_radius_m > 0.0) || !at.allFinite() || !(camera_.eye_m.z() > view.floor_z_m) ||
      !(at.z() > view.floor_z_m))
    return;
  // the tool's disc on the floor (at least 1 mm), hidden where the model is nearer the eye
  gl.Disable(GL_LIGHTING);
  gl.DepthMask(GL_FALSE);
  set_color(gl, kToolShadowColor);
  fill_disc(gl, on_floor(view, at), Vec3::UnitZ(), std::max(view.tool_radius_m, 1e-3));
  gl.DepthMask(GL_TRUE);
}

const uint32_t* Renderer::covering_shadow(const float* flat, std::size_t n, const uint32_t* tris, std::size_t n_indices,
                                          bool light_facing_only, bool cull, std::size_t* kept) {
  *kept = n_indices;
  if (cull) {
    shadow_xy_.resize(2 * n);
    cover_.project(flat, n, shadow_xy_.data());
    shadow_cells_.resize(n);
    cover_.cells(shadow_xy_.data(), n, 0.0f, shadow_cells_.data());
  }
  kept_shadow_.clear();
  for (std::size_t k = 0; k + 2 < n_indices; k += 3) {
    const uint32_t* t = tris + k;
    // a triangle whose corners snapped to a point or a line on the floor casts nothing
    const float* p0 = flat + 3 * t[0];
    const float* p1 = flat + 3 * t[1];
    const float* p2 = flat + 3 * t[2];
    const float area2 = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p1[1] - p0[1]) * (p2[0] - p0[0]);
    if (area2 == 0.0f) continue;
    if (light_facing_only) {
      // a triangle facing the light keeps its winding flattened onto the floor (counter-clockwise seen from above);
      // a closed surface's shadow is the union of those alone
      const float* a = flat + 3 * t[0];
      const float* b = flat + 3 * t[1];
      const float* c = flat + 3 * t[2];
      if (!((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 0.0f)) continue;
    }
    if (cull) {
      const std::size_t before = kept_shadow_.size();
      PixelCover::keep_triangles(shadow_cells_.data(), t, 3, &kept_shadow_);
      if (kept_shadow_.size() == before) continue;
    } else {
      kept_shadow_.insert(kept_shadow_.end(), t, t + 3);
    }
  }
  *kept = kept_shadow_.size();
  return kept_shadow_.data();
}

}  // namespace palpate
