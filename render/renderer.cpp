#include "render/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/tri_mesh.h"
#include "render/renderer_colors.h"

namespace palpate {

using render_colors::kBackground;
using render_colors::kMeshColor;
using render_colors::kWireColor;
using render_colors::set_color;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kSphereSlices = 24;
constexpr int kSphereStacks = 16;

// Unit UV sphere: positions double as normals.
void make_unit_sphere(std::vector<float>* positions, std::vector<uint32_t>* indices) {
  positions->clear();
  indices->clear();
  for (int i = 0; i <= kSphereStacks; ++i) {
    const double theta = kPi * i / kSphereStacks;
    for (int j = 0; j <= kSphereSlices; ++j) {
      const double phi = 2.0 * kPi * j / kSphereSlices;
      positions->push_back(static_cast<float>(std::sin(theta) * std::cos(phi)));
      positions->push_back(static_cast<float>(std::sin(theta) * std::sin(phi)));
      positions->push_back(static_cast<float>(std::cos(theta)));
    }
  }
  const uint32_t row = kSphereSlices + 1;
  for (uint32_t i = 0; i < kSphereStacks; ++i) {
    for (uint32_t j = 0; j < kSphereSlices; ++j) {
      const uint32_t a = i * row + j, b = a + row;
      indices->insert(indices->end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  }
}


// Converts n Vec3 into a grow-only float buffer.
void to_floats(const std::vector<Vec3>& in, std::vector<float>* out) {
  if (out->size() < 3 * in.size()) out->resize(3 * in.size());
  float* dst = out->data();
  for (const Vec3& v : in) {
    *dst++ = static_cast<float>(v.x());
    *dst++ = static_cast<float>(v.y());
    *dst++ = static_cast<float>(v.z());
  }
}

// Pixels kept around each vertex of a layer's redrawn rectangle: more than llvmpipe's 1/256-pixel snapping and a
// pixel centre's half pixel.
constexpr float kPatchPadPx = 2.0f;

}  // namespace

Renderer::Renderer(GlContext* ctx, RenderStyle style, const Camera& camera) : ctx_(ctx), style_(style) {
  make_unit_sphere(&sphere_positions_, &sphere_indices_);
  set_camera(camera);
}

void Renderer::set_camera(const Camera& camera) {
  camera_ = camera;
  view_ = camera_.view_matrix();
  projection_ = camera_.projection_matrix(static_cast<double>(ctx_->width()) / ctx_->height());
  cover_.set(projection_ * view_, ctx_->width(), ctx_->height());
  layer_valid_ = false;  // the layer was drawn from the old camera
}

Eigen::Vector2d Renderer::project(const Vec3& p_m) const {
  const Eigen::Vector4d clip = projection_ * view_ * p_m.homogeneous();
  if (!(clip.w() > 0.0)) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  const double x_ndc = clip.x() / clip.w(), y_ndc = clip.y() / clip.w();
  return {0.5 * (x_ndc + 1.0) * ctx_->width(), 0.5 * (1.0 - y_ndc) * ctx_->height()};
}

void Renderer::draw(const FrameView& view, uint8_t* rgba) {
  ++draws_;
  ctx_->make_current();
  const GlApi& gl = ctx_->gl();
  // both paths draw into the renderer's own framebuffer when there is one, so their pixels compare exactly
  GLint previous = 0;
  const bool own_fbo = ensure_framebuffers(gl);
  if (own_fbo) {
    gl.GetIntegerv(GL_FRAMEBUFFER_BINDING, &previous);
    gl.BindFramebuffer(GL_FRAMEBUFFER, frame_.id());
  }
  // a change of colouring (range, the cut's first vertex) redraws the layer: every colour it holds changes
  const bool color_on = colored(view);
  const bool floor_changed = floor_shown(view) ? !(view.floor_z_m == floor_z_) : std::isfinite(floor_z_);
  if (floor_changed || color_on != color_on_ ||
      (color_on && (view.color_range_m != color_range_m_ || view.first_cut_vertex != color_cut_from_ ||
                    (by_strain(view) ? view.strain_range : 0.0) != strain_range_))) {
    layer_valid_ = false;
    mesh_image_valid_ = false;
    color_on_ = color_on;
    color_range_m_ = view.color_range_m;
    strain_range_ = by_strain(view) ? view.strain_range : 0.0;
    color_cut_from_ = view.first_cut_vertex;
    floor_z_ = floor_shown(view) ? view.floor_z_m : std::numeric_limits<double>::quiet_NaN();
    if (floor_shown(view)) {
      const Vec3 centre(view.floor_centre_m.x(), view.floor_centre_m.y(), view.floor_z_m);
      const double depth = std::max((centre - camera_.eye_m).norm(), 1e-9);
      shadow_grid_m_ = 2.0 * (2.0 * depth * std::tan(0.5 * camera_.fov_y_deg * M_PI / 180.0)) / ctx_->height();
    }
  }
  last_layered_ = own_fbo && layered_ && view.moving_vertices != nullptr && draw_layered(gl, view);
  if (!last_layered_) {
    setup_frame(gl, /*clear=*/true);
    draw_mesh(gl, view);
  }
  draw_tool_shadow(gl, view);
  draw_drop(gl, view);
  draw_tool(gl, view);
  draw_proxy(gl, view);
  draw_blade(gl, view);
  draw_force(gl, view);
  if (samples_ > 0 && own_fbo) resolved_.resolve_from(frame_);
  ctx_->read_rgba(rgba);
  if (smooth_edges_) smoother_.apply(rgba, ctx_->width(), ctx_->height());
  annotate(view, rgba);
  if (own_fbo) gl.BindFramebuffer(GL_FRAMEBUFFER, static_cast<GLuint>(previous));
}

bool Renderer::ensure_framebuffers(const GlApi& gl) {
  if (!fbo_tried_) {
    fbo_tried_ = true;
    // anti-aliased: every framebuffer multisampled alike (copies between them stay exact), the frame resolved into
    // one of a sample a pixel to be read; without multisampling, one sample
    const int w = ctx_->width(), h = ctx_->height();
    int s = samples_asked_ > 1 ? samples_asked_ : 0;
    if (s > 0) {
      auto r = Framebuffer::create(gl, w, h);
      if (r) resolved_ = std::move(r).value();
      else s = 0;
    }
    auto f = Framebuffer::create(gl, w, h, s);
    if (!f && s > 0) f = Framebuffer::create(gl, w, h, s = 0);
    auto l = Framebuffer::create(gl, w, h, s);
    // without them frames go to the context's own buffer and every frame is drawn in full
    if (f && l) {
      frame_ = std::move(f).value();
      layer_ = std::move(l).value();
      samples_ = s;
      // without it every layered frame draws its dynamic part
      if (auto m = Framebuffer::create(gl, w, h, s)) mesh_image_ = std::move(m).value();
    }
    if (samples_ == 0) resolved_ = Framebuffer();
  }
  return frame_.id() != 0;
}

void Renderer::setup_frame(const GlApi& gl, bool clear) const {
  gl.Viewport(0, 0, ctx_->width(), ctx_->height());
  if (clear) {
    gl.ClearColor(kBackground[0], kBackground[1], kBackground[2], kBackground[3]);
    gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LEQUAL);
  gl.ShadeModel(GL_SMOOTH);
  gl.MatrixMode(GL_PROJECTION);
  gl.LoadMatrixd(projection_.data());
  gl.MatrixMode(GL_MODELVIEW);

  // a head light from the upper left, set in eye space so it follows the camera
  gl.LoadIdentity();
  const float light_dir[4] = {-0.3f, 0.4f, 1.0f, 0.0f};
  const float light_diffuse[4] = {0.65f, 0.65f, 0.65f, 1.0f};
  const float light_black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  const float scene_ambient[4] = {0.42f, 0.42f, 0.42f, 1.0f};
  gl.Lightfv(GL_LIGHT0, GL_POSITION, light_dir);
  gl.Lightfv(GL_LIGHT0, GL_DIFFUSE, light_diffuse);
  gl.Lightfv(GL_LIGHT0, GL_AMBIENT, light_black);
  gl.Lightfv(GL_LIGHT0, GL_SPECULAR, light_black);
  gl.LightModelfv(GL_LIGHT_MODEL_AMBIENT, scene_ambient);
  gl.LightModeli(GL_LIGHT_MODEL_TWO_SIDE, GL_TRUE);
  gl.Enable(GL_LIGHT0);
  gl.ColorMaterial(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE);
  gl.Enable(GL_COLOR_MATERIAL);
  gl.Enable(GL_NORMALIZE);
  gl.LoadMatrixd(view_.data());
}

bool Renderer::prepare_mesh(const FrameView& view) {
  const std::vector<Vec3>& vertices = *view.vertices_m;
  const auto& triangles = *view.triangles;
  // an index outside the vertex array would make GL read out of bounds
  const auto n_v = static_cast<int64_t>(vertices.size());
  for (const auto& t : triangles) {
    if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= n_v || t[1] >= n_v || t[2] >= n_v) return false;
  }
  to_floats(vertices, &positions_f_);
  if (style_ != RenderStyle::kWireframe) {
    const std::vector<Vec3>* normals = view.normals;
    if (normals == nullptr || normals->size() != vertices.size()) {
      compute_vertex_normals(vertices, triangles, &computed_normals_);
      normals = &computed_normals_;
    }
    to_floats(*normals, &normals_f_);
  }
  colors_.clear();
  if (colored(view) && fill_drawn()) {
    colors_.resize(4 * vertices.size());
    for (std::size_t v = 0; v < vertices.size(); ++v) {
      const auto c = vertex_color(view, v, vertices[v]);
      std::copy(c.begin(), c.end(), colors_.begin() + static_cast<std::ptrdiff_t>(4 * v));
    }
  }
  shadow_f_.clear();
  if (floor_shown(view)) {
    shadow_f_.resize(3 * vertices.size());
    for (std::size_t v = 0; v < vertices.size(); ++v) {
      const Vec3 f = shadow_point(view, vertices[v]);
      for (int c = 0; c < 3; ++c) shadow_f_[3 * v + static_cast<std::size_t>(c)] = static_cast<float>(f[c]);
    }
  }
  if (lines_drawn()) update_edges(triangles);
  if (style_ == RenderStyle::kBoth && !wire_decided_) decide_wire(vertices.size());
  // a `both` mesh too fine for its lines: no edges to keep up (a layer split and every cut would sort them all)
  if (!lines_drawn()) edge_indices_.clear();
  return true;
}

void Renderer::decide_wire(std::size_t n_vertices) {
  mesh_xy_.resize(2 * n_vertices);
  cover_.project(positions_f_.data(), n_vertices, mesh_xy_.data());
  edge_px_.clear();
  for (std::size_t i = 0; i + 1 < edge_indices_.size(); i += 2) {
    const float* a = &mesh_xy_[2 * edge_indices_[i]];
    const float* b = &mesh_xy_[2 * edge_indices_[i + 1]];
    const float len = std::hypot(a[0] - b[0], a[1] - b[1]);
    if (std::isfinite(len)) edge_px_.push_back(len);
  }
  if (edge_px_.empty()) return;  // nothing in front of the eye yet: decided on a later frame
  auto mid = edge_px_.begin() + static_cast<std::ptrdiff_t>(edge_px_.size() / 2);
  std::nth_element(edge_px_.begin(), mid, edge_px_.end());
  median_edge_px_ = *mid;
  wire_on_ = !(wire_min_edge_px_ > 0.0) || median_edge_px_ >= wire_min_edge_px_;
  wire_decided_ = true;
}

void Renderer::draw_mesh(const GlApi& gl, const FrameView& view) {
  if (view.vertices_m == nullptr || view.triangles == nullptr || view.triangles->empty()) return;
  if (!prepare_mesh(view)) return;
  static_assert(sizeof(std::array<int32_t, 3>) == 3 * sizeof(uint32_t), "triangles are packed index triples");
  const auto& triangles = *view.triangles;
  if (!shadow_f_.empty()) {
    draw_floor(gl, view);
    std::size_t n_shadow = 0;
    static_assert(sizeof(uint32_t) == sizeof(int32_t));
    const uint32_t* shadow = covering_shadow(shadow_f_.data(), view.vertices_m->size(),
                                             reinterpret_cast<const uint32_t*>(triangles.data()->data()),
                                             3 * triangles.size(), view.closed_surface, /*cull=*/false, &n_shadow);
    draw_shadow(gl, shadow_f_.data(), shadow, n_shadow);
  }
  draw_fill(gl, positions_f_.data(), normals_f_.data(), colors_.empty() ? nullptr : colors_.data(),
            triangles.data()->data(), 3 * triangles.size());
  draw_lines(gl, positions_f_.data(), edge_indices_);
}

bool Renderer::draw_layered(const GlApi& gl, const FrameView& view) {
  if (view.vertices_m == nullptr || view.triangles == nullptr || view.triangles->empty()) return false;
  const std::vector<Vec3>& vertices = *view.vertices_m;
  const auto& triangles = *view.triangles;
  const bool same_layer = layer_valid_ && view.layer_epoch == layer_epoch_;
  const bool fresh = same_layer && vertices.size() == layer_vertices_ && triangles.size() == layer_triangles_ &&
                     view.topology_epoch == layer_topology_;
  if (!fresh) {
    dynamic_changed_ = true;
    mesh_image_valid_ = false;
  }
  if (!fresh && same_layer && view.static_part_kept && vertices.size() >= layer_vertices_) {
    if (!resplit(view)) return false;
  } else if (!fresh) {
    // a layer of the same camera and mesh with no lines is redrawn only where the parts changed (layer_patch.h)
    const bool patch = layer_patching_ && layer_valid_ && !lines_drawn() && vertices.size() >= layer_vertices_ &&
                       positions_f_.size() >= 3 * layer_vertices_;
    // (and the shadows' rectangle, from the positions flattened onto the floor)
    const bool shadow_patch = patch && !shadow_f_.empty() && shadow_f_.size() >= 3 * layer_vertices_;
    if (patch) patch_.keep(layers_.affected_vertices(), layers_.local_vertices(), positions_f_, normals_f_, layer_vertices_);
    if (shadow_patch)
      shadow_patch_.keep(layers_.affected_vertices(), layers_.local_vertices(), shadow_f_, {}, layer_vertices_);
    layer_valid_ = false;
    for (int32_t v : *view.moving_vertices)
      if (v < 0 || static_cast<std::size_t>(v) >= vertices.size()) return false;
    if (!prepare_mesh(view)) return false;
    layers_.split(vertices.size(), triangles, edge_indices_, *view.moving_vertices);
    // the dynamic part's own vertex array, taken from the whole mesh's once per layer
    fill_local_vertices();
    const auto& local = layers_.local_vertices();
    const PixelRect whole{0, 0, ctx_->width(), ctx_->height()};
    PixelRect rect = patch ? patch_.rect(cover_, local, positions_f_, normals_f_, vertices.size(), kPatchPadPx,
                                         whole.x1, whole.y1)
                           : whole;
    // a floor that was not drawn before (or one without the old shadows kept) is drawn whole
    if (patch && !shadow_f_.empty()) {
      if (!shadow_patch) {
        rect = whole;
      } else {
        const PixelRect s = shadow_patch_.rect(cover_, local, shadow_f_, {}, vertices.size(), kPatchPadPx, whole.x1,
                                               whole.y1);
        if (s.area() > 0) {
          if (rect.area() == 0) rect = s;
          rect = {std::min(rect.x0, s.x0), std::min(rect.y0, s.y0), std::max(rect.x1, s.x1), std::max(rect.y1, s.y1)};
        }
      }
    }
    // the static part, drawn as a full redraw would draw it: fill, then lines (less what reaches no centre)
    // (multisampled, a triangle between pixel centres still covers samples: nothing is left out)
    const bool cull = culling_ && samples_ == 0;
    const bool part = rect.area() < whole.area();
    if (cull || part) {
      mesh_xy_.resize(2 * vertices.size());
      place(positions_f_.data(), vertices.size(), &mesh_xy_, &mesh_fill_cells_, &mesh_line_cells_);
    }
    const std::vector<uint32_t>* static_tris = &layers_.static_triangles();
    if (part) {
      patch_tris_.clear();
      triangles_in_rect(mesh_xy_.data(), static_tris->data(), static_tris->size(), rect, &patch_tris_);
      static_tris = &patch_tris_;
    }
    std::size_t n_fill = 0;
    const uint32_t* fill =
        covering_triangles(cull, mesh_fill_cells_.data(), static_tris->data(), static_tris->size(), &n_fill);
    const std::vector<uint32_t>& static_lines =
        covering_lines(cull, mesh_line_cells_.data(), layers_.static_edges());
    gl.BindFramebuffer(GL_FRAMEBUFFER, layer_.id());
    // outside the rectangle the layer holds what this draw would put there
    if (part) {
      gl.Enable(GL_SCISSOR_TEST);
      gl.Scissor(rect.x0, rect.y0, rect.x1 - rect.x0, rect.y1 - rect.y0);
    }
    setup_frame(gl, /*clear=*/true);
    if (!shadow_f_.empty()) {
      // the floor and the static part's shadow (those of its triangles whose shadow reaches the rectangle)
      draw_floor(gl, view);
      const std::vector<uint32_t>* shadow_tris = &layers_.static_triangles();
      if (part) {
        shadow_xy_.resize(2 * vertices.size());
        cover_.project(shadow_f_.data(), vertices.size(), shadow_xy_.data());
        shadow_tris_.clear();
        triangles_in_rect(shadow_xy_.data(), shadow_tris->data(), shadow_tris->size(), rect, &shadow_tris_);
        shadow_tris = &shadow_tris_;
      }
      std::size_t n_shadow = 0;
      const uint32_t* shadow = covering_shadow(shadow_f_.data(), vertices.size(), shadow_tris->data(),
                                               shadow_tris->size(), view.closed_surface, culling_ && samples_ == 0, &n_shadow);
      draw_shadow(gl, shadow_f_.data(), shadow, n_shadow);
    }
    draw_fill(gl, positions_f_.data(), normals_f_.data(), colors_.empty() ? nullptr : colors_.data(), fill, n_fill);
    draw_lines(gl, positions_f_.data(), static_lines);
    gl.Disable(GL_SCISSOR_TEST);
    last_layer_px_ = rect.area();
    gl.BindFramebuffer(GL_FRAMEBUFFER, frame_.id());
    if (cull) {
      local_xy_.resize(2 * local.size());
      place(local_positions_f_.data(), local.size(), &local_xy_, &local_fill_cells_, &local_line_cells_);
    }
    layer_valid_ = true;
    layer_culled_ = cull;
    layer_epoch_ = view.layer_epoch;
    layer_vertices_ = vertices.size();
    layer_triangles_ = triangles.size();
    layer_topology_ = view.topology_epoch;
    ++layer_builds_;
  } else if (update_local_vertices(view)) {
    dynamic_changed_ = true;
    mesh_image_valid_ = false;
    // only the affected vertices (the first local ones) move
    if (culling_ && layer_culled_)
      place(local_positions_f_.data(), layers_.affected_vertices().size(), &local_xy_, &local_fill_cells_,
            &local_line_cells_);
  } else if (mesh_image_valid_) {
    // nothing the dynamic part draws has changed since its image was kept: the image is what it would draw
    frame_.copy_from(mesh_image_);
    setup_frame(gl, /*clear=*/false);
    return true;
  }
  // a layer built without culling has no cells for its local vertices
  const bool cull = culling_ && layer_culled_;
  std::size_t n_fill = 0;
  const auto& dynamic_tris = layers_.dynamic_triangles();
  const uint32_t* fill =
      covering_triangles(cull, local_fill_cells_.data(), dynamic_tris.data(), dynamic_tris.size(), &n_fill);
  const std::vector<uint32_t>& lines =
      covering_lines(cull, local_line_cells_.data(), layers_.dynamic_edges());
  frame_.copy_from(layer_);
  setup_frame(gl, /*clear=*/false);
  // the moving part's shadow, under whatever the layer holds nearer the eye
  if (!local_shadow_f_.empty()) {
    std::size_t n_shadow = 0;
    const uint32_t* shadow = covering_shadow(local_shadow_f_.data(), layers_.local_vertices().size(), dynamic_tris.data(),
                                             dynamic_tris.size(), view.closed_surface, culling_ && samples_ == 0, &n_shadow);
    draw_shadow(gl, local_shadow_f_.data(), shadow, n_shadow);
  }
  // the polygon offset keeps every fill at least one depth unit behind a line on it, so drawing moving fills
  // after cached lines changes no pixel; a moving and a static fill at exactly equal depth (an edge seen
  // edge-on) go to the moving one here and to the later triangle in a full redraw
  draw_fill(gl, local_positions_f_.data(), local_normals_f_.data(),
            local_colors_.empty() ? nullptr : local_colors_.data(), fill, n_fill);
  draw_lines(gl, local_positions_f_.data(), lines);
  ++dynamic_draws_;
  // kept once the dynamic part holds still for a frame: a part that changes every frame costs no extra copy
  if (!dynamic_changed_ && mesh_image_.id() != 0) {
    mesh_image_.copy_from(frame_);
    gl.BindFramebuffer(GL_FRAMEBUFFER, frame_.id());
    mesh_image_valid_ = true;
  }
  dynamic_changed_ = false;
  return true;
}

void Renderer::draw_fill(const GlApi& gl, const float* positions, const float* normals, const uint8_t* colors,
                         const void* indices, std::size_t count) const {
  if (!fill_drawn() || count == 0) return;
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, positions);
  gl.Enable(GL_LIGHTING);
  gl.EnableClientState(GL_NORMAL_ARRAY);
  gl.NormalPointer(GL_FLOAT, 0, normals);
  // push the fill back so the wireframe sits on the surface (without lines, `both` draws as `solid` does)
  if (style_ == RenderStyle::kBoth && lines_drawn()) {
    gl.Enable(GL_POLYGON_OFFSET_FILL);
    gl.PolygonOffset(1.0f, 1.0f);
  }
  set_color(gl, kMeshColor);
  if (colors) {
    gl.EnableClientState(GL_COLOR_ARRAY);
    gl.ColorPointer(4, GL_UNSIGNED_BYTE, 0, colors);
  }
  gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(count), GL_UNSIGNED_INT, indices);
  if (colors) gl.DisableClientState(GL_COLOR_ARRAY);
  gl.Disable(GL_POLYGON_OFFSET_FILL);
  gl.DisableClientState(GL_NORMAL_ARRAY);
  gl.DisableClientState(GL_VERTEX_ARRAY);
}

void Renderer::draw_lines(const GlApi& gl, const float* positions, const std::vector<uint32_t>& edges) const {
  // each edge once as a line: llvmpipe's polygon-mode lines cost about three times as much
  if (!lines_drawn() || edges.empty()) return;
  gl.EnableClientState(GL_VERTEX_ARRAY);
  gl.VertexPointer(3, GL_FLOAT, 0, positions);
  gl.Disable(GL_LIGHTING);
  gl.LineWidth(1.0f);
  set_color(gl, kWireColor);
  gl.DrawElements(GL_LINES, static_cast<GLsizei>(edges.size()), GL_UNSIGNED_INT, edges.data());
  gl.DisableClientState(GL_VERTEX_ARRAY);
}

}  // namespace palpate
