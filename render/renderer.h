#pragma once
/// Renderer: draws the deformed mesh, the tool, the proxy spring and the blade into an off-screen GL context.

#include <array>
#include <cstdint>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "core/scene_enums.h"
#include "core/types.h"
#include "render/annotate.h"
#include "render/camera.h"
#include "render/edge_smooth.h"
#include "render/framebuffer.h"
#include "render/gl_context.h"
#include "render/layer_patch.h"
#include "render/mesh_layers.h"
#include "render/pixel_cover.h"

namespace palpate {


/// What one frame shows; pointers valid during draw() only.
struct FrameView {
  const std::vector<Vec3>* vertices_m = nullptr;                  ///< mesh vertex positions (n_v), metres
  const std::vector<std::array<int32_t, 3>>* triangles = nullptr;  ///< vertex indices (n_t)
  const std::vector<Vec3>* normals = nullptr;  ///< per vertex (n_v); null or wrong size: computed here
  Vec3 tool_pos_m = Vec3::Zero();              ///< tool sphere centre, metres
  double tool_radius_m = 0.0;                  ///< tool sphere radius, metres (0: not drawn)
  bool in_contact = false;                     ///< tool drawn red when true
  bool show_proxy = false;                     ///< draw the proxy spring tool -> proxy
  Vec3 proxy_pos_m = Vec3::Zero();             ///< proxy (contact) point, metres
  bool tool_at_proxy = false;                  ///< draw the tool sphere at proxy_pos_m (a sphere tool resting on the surface)
  bool show_drop = false;                      ///< a free tool's drop line straight down to the surface, and a dark
                                               ///< disc where it lands (depth in a still frame)
  Vec3 drop_to_m = Vec3::Zero();               ///< where the drop line meets the surface, metres
  Vec3 drop_normal = Vec3::UnitZ();            ///< the surface's normal there (unit)
  bool show_blade = false;                     ///< draw the blade blade_tip_m -> blade_end_m (cut mode)
  Vec3 blade_tip_m = Vec3::Zero();             ///< blade tip (the tool position), metres
  Vec3 blade_end_m = Vec3::Zero();             ///< blade end toward the handle, metres
  /// Vertices that may move until layer_epoch changes (e.g. those bound to the lattice region); the rest of
  /// the mesh is drawn once into a cached layer. Null: every vertex may move, the mesh is drawn in full.
  const std::vector<int32_t>* moving_vertices = nullptr;
  /// Changes whenever moving_vertices or the triangles change (region moved, mesh cut): the layer is redrawn.
  uint64_t layer_epoch = 0;
  /// Changes whenever the triangles change.
  uint64_t topology_epoch = 0;
  /// True when, within one layer_epoch, triangles change or are added only where a moving vertex is and new
  /// vertices are moving (a cut inside the moving part): the layer is kept and only the dynamic part is split
  /// again. False: any change of the triangles redraws the layer.
  bool static_part_kept = false;
  /// Colour by displacement: each vertex by its distance from rest_m (one per vertex), the map's top
  /// (render/annotate.h) at color_range_m and beyond. Null, or a range that is not positive: one colour.
  const std::vector<Vec3>* rest_m = nullptr;
  double color_range_m = 0.0;
  /// Colour by strain instead: each vertex by its value here (one per vertex, a fraction), the map's top at
  /// strain_range and beyond; the legend says "strain" in per cent. Null, or a range that is not positive: as above.
  const std::vector<float>* vertex_value = nullptr;
  double strain_range = 0.0;
  /// Vertices from this index on were made by a cut: drawn in the cut's colour (-1: none).
  int64_t first_cut_vertex = -1;
  /// The force arrow: force_N (the force sent to the device) drawn from the proxy, its value beside its tip; an
  /// arrow of force_scale_N is a fifth of the picture's height at the proxy's depth (<= 0: no arrow, and none in
  /// the legend).
  bool show_force = false;
  Vec3 force_N = Vec3::Zero();
  double force_scale_N = 0.0;
  /// The legend (displacement colours, the cut's colour, the arrow's scale) in the top-right corner.
  bool show_legend = false;
  /// An inset in the bottom-left corner: the force's magnitude over the last force_trace_s seconds, one value a
  /// drawn frame (the largest a tick sent since the frame before), oldest first (null: none), from 0 to
  /// force_trace_max_N.
  const std::vector<float>* force_trace = nullptr;
  double force_trace_max_N = 0.0;
  double force_trace_s = 2.0;
  std::size_t force_trace_frames = 120;  ///< values that span force_trace_s (the plot's full width)
  /// A floor at height floor_z_m (world z; NaN: none), a square of half-side floor_half_m around floor_centre_m
  /// (x, y), with the shadows the model and the tool cast on it from a light above (kShadowLight): where the tool is
  /// above the surface and the model above the floor, in a still frame.
  double floor_z_m = std::numeric_limits<double>::quiet_NaN();
  Vec3 floor_centre_m = Vec3::Zero();
  double floor_half_m = 0.0;
  /// The surface is closed: its shadow is that of the triangles facing the light alone (half as many drawn).
  bool closed_surface = false;
};

/// The direction the floor's light travels (world, not unit): from above, behind and to the left of the default
/// view (front-right-above), so shadows fall toward the viewer and to the right, where they are seen.
inline const Vec3 kShadowLight{0.35, -0.25, -1.0};

/// Draws frames with legacy fixed-function GL; keeps a pointer to the context (which must outlive it) and
/// grow-only scratch buffers; not copyable. Thread: the thread that owns the context.
///
/// Cost follows what moves: when a view names its moving vertices, the triangles and edges that cannot change
/// are drawn once into a cached colour + depth layer; each frame copies the layer and draws only the rest, the
/// tool and the overlays, with depth tests that give the pixels of a full redraw (see draw()). The rest is drawn
/// from a compact vertex array of its own (MeshLayers' local vertices), so a frame hands GL and converts only the
/// vertices it draws, not the whole mesh's. Of what the layered path draws, triangles and lines that reach no
/// pixel centre are left out (PixelCover): on a mesh denser than the image that is most of them, and no pixel
/// changes.
class Renderer {
 public:
  /// Prepares the tool sphere and the camera matrices for ctx's size.
  Renderer(GlContext* ctx, RenderStyle style, const Camera& camera);
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Draws the frame and reads it into rgba (w*h*4, top-down); a mesh with an out-of-range index is skipped.
  void draw(const FrameView& view, uint8_t* rgba);
  /// false: always redraw the whole mesh, ignoring FrameView::moving_vertices (a reference for the cached path).
  void set_layered(bool on) {
    layered_ = on;
    mesh_image_valid_ = false;
  }
  /// `both` style: the wireframe is drawn only when the mesh's median edge is at least this long on screen, in
  /// pixels (0: always). Shorter, its lines cover every pixel of the surface and show no edge: a 940k-triangle
  /// bunny at 640 x 480 (edges 0.2-0.6 px) comes out as a dark silhouette. Decided once, on the first frame
  /// that shows a mesh, so every frame of a run looks alike; set it before that frame.
  void set_wire_min_edge_px(double px) { wire_min_edge_px_ = px; }
  /// Median on-screen edge length of the mesh the wireframe was decided on, in pixels (NaN before, and for
  /// styles other than `both`), and whether the wireframe is drawn.
  double median_edge_px() const { return median_edge_px_; }
  bool wire_drawn() const { return lines_drawn(); }
  /// false: the layered path draws every triangle and line, even those that reach no pixel centre.
  void set_culling(bool on) {
    culling_ = on;
    mesh_image_valid_ = false;
  }
  /// Samples a pixel for anti-aliased edges (0 or 1: one; set before the first draw). When the context has no
  /// multisampled framebuffers, frames are drawn one sample a pixel; samples() says what is used.
  void set_samples(int n) { samples_asked_ = n; }
  /// true: edges are smoothed in the image read back (render/edge_smooth.h), before the legend and labels are written
  /// into it; its cost follows the pixels that changed since the last frame.
  void set_smooth_edges(bool on) {
    smooth_edges_ = on;
    smoother_.reset();
  }
  bool smooth_edges() const { return smooth_edges_; }
  int samples() const { return samples_; }
  /// false: a new layer is always drawn whole; true (the default): when the camera is the same and no lines are
  /// drawn, only the rectangle where the static and moving parts changed is redrawn (render/layer_patch.h).
  void set_layer_patching(bool on) { layer_patching_ = on; }
  /// Pixels the last layer build redrew (the whole frame's when drawn whole).
  int64_t last_layer_px() const { return last_layer_px_; }
  /// Primitives the last layered draw had in its dynamic part, and those it drew.
  struct Drawn {
    std::size_t triangles = 0, triangles_drawn = 0, lines = 0, lines_drawn = 0;
  };
  const Drawn& last_drawn() const { return last_drawn_; }
  /// The corners the legend and the force trace are drawn in: of the four, those covering the least of the model (its
  /// triangles on a grid of 8-pixel cells) on the first frame that shows either (top-right and bottom-left when
  /// free), kept for the run.
  Corner legend_corner() const { return legend_corner_; }
  Corner trace_corner() const { return trace_corner_; }
  /// Whether the last draw() used the cached layer.
  bool last_draw_layered() const { return last_layered_; }
  /// Frames drawn so far (calls of draw()).
  int64_t draws() const { return draws_; }
  /// Times the cached layer was redrawn.
  int64_t layer_builds() const { return layer_builds_; }
  /// Times the triangles changed within a layer and only its dynamic part was split again.
  int64_t resplits() const { return resplits_; }
  /// Layered frames that drew the dynamic part; the others copied the image of the last one that did (nothing
  /// in the dynamic part had changed since: same layer, triangles, positions and normals).
  int64_t dynamic_draws() const { return dynamic_draws_; }
  /// Pixel coordinates (x right, y down, origin top-left) of a world point; NaN when behind the camera.
  Eigen::Vector2d project(const Vec3& p_m) const;
  /// Size in pixels of the frames draw() reads (the context's).
  int width() const { return ctx_->width(); }
  int height() const { return ctx_->height(); }
  /// Replaces the camera (e.g. an orbiting view).
  void set_camera(const Camera& camera);
  /// The current camera.
  const Camera& camera() const { return camera_; }

 private:
  void setup_frame(const GlApi& gl, bool clear) const;
  // index check and positions/normals for GL; false when an index is out of range
  bool prepare_mesh(const FrameView& view);
  void draw_mesh(const GlApi& gl, const FrameView& view);
  // the fill of `count` triangle indices and the lines of an edge list, from the given vertex arrays (3 floats
  // per vertex: the whole mesh's positions_f_ / normals_f_, or the dynamic part's local ones)
  void draw_fill(const GlApi& gl, const float* positions, const float* normals, const uint8_t* colors,
                 const void* indices, std::size_t count) const;
  void draw_lines(const GlApi& gl, const float* positions, const std::vector<uint32_t>& edges) const;
  // creates the frame and layer framebuffers once; false when the context has none
  bool ensure_framebuffers(const GlApi& gl);
  // layered path: redraws the layer when the epoch changed, else updates the affected vertices; false: skip mesh
  bool draw_layered(const GlApi& gl, const FrameView& view);
  // within a layer: splits the changed triangles' dynamic part again and keeps the layer (static_part_kept)
  bool resplit(const FrameView& view);
  // the dynamic part's local vertex arrays from the whole mesh's (positions_f_, normals_f_)
  void fill_local_vertices();
  // copies the affected vertices' positions and normals (computed from the dynamic triangles when the view has
  // none) into the local arrays: O(dynamic part), whatever the mesh's size; true when any value changed
  bool update_local_vertices(const FrameView& view);
  void draw_tool(const GlApi& gl, const FrameView& view) const;
  void draw_proxy(const GlApi& gl, const FrameView& view) const;
  void draw_drop(const GlApi& gl, const FrameView& view) const;
  // a 24-sided disc of radius r around c, facing n, in the current colour
  static void fill_disc(const GlApi& gl, const Vec3& c, const Vec3& n, double r);
  void draw_blade(const GlApi& gl, const FrameView& view) const;
  // the force arrow (GL) and, into the image read back, the legend and the arrow's value
  void draw_force(const GlApi& gl, const FrameView& view);
  // the floor (no depth written: everything is drawn over it) and shadows: the triangles (count indices) of a
  // 3-float array of positions already flattened onto the floor, and the tool's
  static bool floor_shown(const FrameView& view) { return std::isfinite(view.floor_z_m) && view.floor_half_m > 0.0; }
  void draw_floor(const GlApi& gl, const FrameView& view) const;
  void draw_shadow(const GlApi& gl, const float* flat, const void* indices, std::size_t count) const;
  void draw_tool_shadow(const GlApi& gl, const FrameView& view) const;
  // p flattened onto the floor along kShadowLight; and so, snapped to the shadow's grid (shadow_grid_m_) there
  static Vec3 on_floor(const FrameView& view, const Vec3& p);
  Vec3 shadow_point(const FrameView& view, const Vec3& p) const;
  void annotate(const FrameView& view, uint8_t* rgba);
  // which cells of kCoverCellPx pixels of the picture the view's mesh covers (cover_w() x cover_h(), row-major)
  static constexpr int kCoverCellPx = 8;
  int cover_w() const { return (ctx_->width() + kCoverCellPx - 1) / kCoverCellPx; }
  int cover_h() const { return (ctx_->height() + kCoverCellPx - 1) / kCoverCellPx; }
  std::vector<uint8_t> model_cover(const FrameView& view) const;
  // whether the view colours its vertices, and the colour of vertex v (its position p)
  static bool by_strain(const FrameView& view) { return view.vertex_value != nullptr && view.strain_range > 0.0; }
  static bool colored(const FrameView& view) {
    return view.rest_m != nullptr && (view.color_range_m > 0.0 || view.first_cut_vertex >= 0 || by_strain(view));
  }
  static std::array<uint8_t, 4> vertex_color(const FrameView& view, std::size_t v, const Vec3& p);
  bool fill_drawn() const { return style_ != RenderStyle::kWireframe; }
  bool lines_drawn() const {
    return style_ == RenderStyle::kWireframe || (style_ == RenderStyle::kBoth && (!wire_decided_ || wire_on_));
  }
  // decides the `both` wireframe from the mesh in positions_f_ and edge_indices_ (see set_wire_min_edge_px)
  void decide_wire(std::size_t n_vertices);
  // window positions of the first n vertices of a 3-float array into xy (sized for them), and their cells for
  // fills and lines (grown to xy's size when smaller)
  void place(const float* positions, std::size_t n, std::vector<float>* xy,
             std::vector<PixelCover::Cell>* fill_cells, std::vector<PixelCover::Cell>* line_cells) const;
  // the triangles (count indices) and lines of the layered path that reach a pixel centre, given their
  // vertices' cells (read only when cull); everything when not cull, nothing when the style leaves them out.
  // Points at kept_* or at the input.
  const uint32_t* covering_triangles(bool cull, const PixelCover::Cell* cells, const uint32_t* tris,
                                     std::size_t count, std::size_t* kept);
  const std::vector<uint32_t>& covering_lines(bool cull, const PixelCover::Cell* cells,
                                              const std::vector<uint32_t>& lines);
  // Rebuilds the unique edge list when the triangles changed since the last frame.
  void update_edges(const std::vector<std::array<int32_t, 3>>& triangles);

  GlContext* ctx_;
  RenderStyle style_;
  Camera camera_;
  Eigen::Matrix4d view_;        // world -> eye (4 x 4)
  Eigen::Matrix4d projection_;  // eye -> clip (4 x 4)
  std::vector<float> positions_f_;       // mesh positions for GL (3 n_v)
  std::vector<float> normals_f_;         // mesh normals for GL (3 n_v)
  std::vector<Vec3> computed_normals_;   // normals when the view has none (n_v)
  std::vector<uint8_t> colors_;          // mesh vertex colours, RGBA (4 n_v; empty: one colour)
  std::vector<uint8_t> local_colors_;    // the dynamic part's vertex colours (4 n_local; empty: one colour)
  std::vector<float> shadow_f_;          // mesh positions flattened onto the floor (3 n_v; empty: no floor)
  std::vector<float> local_shadow_f_;    // the dynamic part's, flattened (3 n_local; empty: no floor)
  std::vector<float> shadow_xy_;         // window positions of shadow_f_, for a partial layer build (2 n_v)
  std::vector<uint32_t> shadow_tris_;    // scratch: the static triangles whose shadow reaches that rectangle
  std::vector<PixelCover::Cell> shadow_cells_;  // scratch: the cells of shadow positions (n_v or n_local)
  std::vector<uint32_t> kept_shadow_;    // scratch: the shadow triangles that reach a pixel centre
  // the triangles (n_indices) of `flat` (n vertices, 3 floats each, on the floor) whose shadow reaches a pixel centre
  // (all of them without culling); points at kept_shadow_ or at the input
  const uint32_t* covering_shadow(const float* flat, std::size_t n, const uint32_t* tris, std::size_t n_indices,
                                  bool light_facing_only, bool cull, std::size_t* kept);
  LayerPatch shadow_patch_;              // the old layer's parts' shadows, for the rectangle a redraw must cover
  double floor_z_ = std::numeric_limits<double>::quiet_NaN();  // the floor the layer was drawn with
  // the grid the shadows' corners are snapped to on the floor, about two pixels where the floor's centre is seen: a
  // flat-coloured shadow loses a pixel of outline at most, and the triangles that fall to a point or a line on it
  // (most of a fine mesh's) are not drawn
  double shadow_grid_m_ = 0.0;
  double color_range_m_ = 0.0;           // the colouring the layer was drawn with (a change redraws it)
  double strain_range_ = 0.0;
  int64_t color_cut_from_ = -1;
  bool color_on_ = false;
  Vec3 arrow_tip_m_ = Vec3::Zero();      // where the last arrow's tip was (for its label)
  bool arrow_drawn_ = false;
  // the corners of the legend and the force trace, chosen on the first frame that shows either (Renderer::annotate)
  bool insets_placed_ = false;
  Corner legend_corner_ = Corner::kTopRight, trace_corner_ = Corner::kBottomLeft;
  std::vector<uint64_t> edge_keys_;      // scratch for the edge build: (lo << 32 | hi) per half edge
  std::vector<uint32_t> edge_indices_;   // unique mesh edges as GL_LINES pairs (2 n_e)
  uint64_t edges_hash_ = 0;              // hash of the triangles edge_indices_ was built from
  std::size_t edges_triangles_ = 0;      // triangle count edge_indices_ was built from
  std::vector<float> sphere_positions_;  // unit sphere, also its normals (3 n_s)
  std::vector<uint32_t> sphere_indices_; // unit sphere triangles (3 n_st)

  // cached layer
  bool layered_ = true;                  // use moving_vertices when given
  bool fbo_tried_ = false;               // framebuffers were attempted (they stay empty on failure)
  Framebuffer frame_;                    // where frames are drawn and read (both paths, so they match)
  Framebuffer layer_;                    // static part: colour + depth
  Framebuffer mesh_image_;               // the layer with the dynamic part drawn over it, before the tool
  Framebuffer resolved_;                 // multisampled frames: the frame resolved to one sample a pixel, read back
  int samples_asked_ = 0, samples_ = 0;  // samples a pixel asked for, and used
  bool smooth_edges_ = false;            // edges smoothed in the image read back
  EdgeSmoother smoother_;
  bool mesh_image_valid_ = false;        // mesh_image_ holds what the dynamic part would draw now
  bool dynamic_changed_ = true;          // the last layered frame changed the dynamic part (or built the layer)
  int64_t dynamic_draws_ = 0;            // layered frames that drew the dynamic part
  MeshLayers layers_;                    // static / dynamic split for the layer's epoch
  std::vector<float> local_positions_f_; // the dynamic part's vertex positions for GL (3 n_local)
  std::vector<float> local_normals_f_;   // the dynamic part's vertex normals for GL (3 n_local)
  std::vector<Vec3> local_normals_;      // affected vertices' normals when the view has none (n_affected)
  bool layer_valid_ = false;             // layer_ holds the static part of layer_epoch_
  uint64_t layer_epoch_ = 0;             // epoch the layer was drawn for
  std::size_t layer_vertices_ = 0, layer_triangles_ = 0;  // mesh size the layer was drawn for
  uint64_t layer_topology_ = 0;          // topology epoch the dynamic part was split for
  int64_t resplits_ = 0;                 // dynamic parts split again with the layer kept
  bool culling_ = true;                  // leave out what reaches no pixel centre (layered path)
  PixelCover cover_;                     // the camera and viewport for that
  std::vector<float> mesh_xy_;           // window positions of the whole mesh, for a layer build (2 n_v)
  std::vector<float> local_xy_;          // window positions of the local vertices (2 n_local)
  std::vector<PixelCover::Cell> mesh_fill_cells_, mesh_line_cells_;    // (n_v)
  std::vector<PixelCover::Cell> local_fill_cells_, local_line_cells_;  // (n_local)
  double wire_min_edge_px_ = kWireMinEdgePxDefault;  // see set_wire_min_edge_px
  bool wire_decided_ = false, wire_on_ = true;
  bool layer_culled_ = false;            // the layer was built with culling on (local cells are valid)
  double median_edge_px_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<float> edge_px_;           // scratch: on-screen edge lengths for the decision
  std::vector<uint32_t> kept_triangles_, kept_lines_;  // what a layered draw hands GL after culling
  Drawn last_drawn_;
  bool last_layered_ = false;
  int64_t layer_builds_ = 0;
  bool layer_patching_ = true;           // a layer may be redrawn in part (set_layer_patching)
  LayerPatch patch_;                     // the old layer's parts, to find the rectangle a redraw must cover
  std::vector<uint32_t> patch_tris_;     // scratch: the static triangles reaching that rectangle
  int64_t last_layer_px_ = 0;            // pixels the last layer build redrew
  int64_t draws_ = 0;
};

}  // namespace palpate
