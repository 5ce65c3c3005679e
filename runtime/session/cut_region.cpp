#include "runtime/session/cut_region.h"

#include <algorithm>

#include "core/tri_mesh.h"
#include "sim/cut/cut.h"

namespace palpate {

CutRegion::CutRegion(const Scene& scene, const Model& model, FrameStats* stats)
    : scene_(scene),
      grid_(model.grid),
      stats_(stats),
      cut_(model.rest, model.bindings, &model.grid, scene.lattice.level, scene.blade_length_m),
      uncut_vertices_(static_cast<int64_t>(model.rest.vertices_m.size())) {
  // one lattice over every solid cell: a region centred in the grid reaching all of it
  const int level = scene.lattice.level;
  const int n = model.grid.cells_per_axis(level);
  auto lat = build_lattice(model.grid, scene.lattice, region_cells(model.grid, level, {n / 2, n / 2, n / 2}, n));
  cut_.set_max_cut_work_per_apply(kCutWorkPerFrame);
  cut_.set_incision_gap_m(scene.blade_width_m);
  if (!lat) return;
  // the object starts at rest in its own shape, as it lay before the blade came (taken as resting under gravity
  // already): nothing moves, and nothing is stepped, until a piece is cut free
  lattice_ = std::move(lat).value();
  redraw_.emplace(*lattice_, model.grid.num_cells(level), kRedrawTolerance * (model.grid.cube().max_m - model.grid.cube().min_m).x());
  floor_z_m_ = lattice_->rest_m.front().z();
  for (const Vec3& r : lattice_->rest_m) floor_z_m_ = std::min(floor_z_m_, r.z());
  stats_->lattice_nodes = lattice_->num_nodes();
  stats_->lattice_springs = lattice_->springs.size();
  stats_->lattice_vertices = model.rest.vertices_m.size();
}

void CutRegion::add_sample(const HapticSample& s) {
  // the blade cuts whatever it sweeps while the button is held (the servo's in-material test only sets the
  // resistance: the lattice reaches past the surface, and its springs there must be cut too)
  blade_cutting_ = (s.buttons & 1u) != 0 && !s.input_rejected;
  blade_tip_m_ = s.tool_pos_m;
  blade_end_m_ = s.tool_pos_m + scene_.blade_length_m * s.blade_axis;
  cut_.add_sample(s.tool_pos_m, s.blade_axis, blade_cutting_);
}

bool CutRegion::begin_frame(const DeformedMesh& mesh) {
  cutting_ = false;
  topology_changed_ = false;
  first_new_ = cut_.rest_vertices_m().size();
  if (!lattice_ || !cut_.has_work()) return false;
  const CutReport rep = cut_.apply(&*lattice_, mesh.vertices_m);
  cutting_ = true;
  ++stats_->frames_cutting;
  stats_->springs_cut += rep.springs_cut;
  const auto deferred = static_cast<int64_t>(cut_.deferred_springs());
  stats_->springs_deferred_max = std::max(stats_->springs_deferred_max, deferred);
  stats_->frames_deferring += deferred > 0 ? 1 : 0;
  stats_->cut_work_max = std::max<int64_t>(stats_->cut_work_max, rep.work());
  stats_->triangles_added += rep.split.triangles_added;
  stats_->vertices_added += rep.split.vertices_added;
  stats_->lattice_vertices = std::max(stats_->lattice_vertices, cut_.rest_vertices_m().size());
  if (rep.springs_cut > 0) {
    contact_.update(*lattice_, grid_);
    stats_->free_nodes = static_cast<int64_t>(contact_.free_nodes().size());
    pieces_.update(*lattice_, contact_.free_nodes());
  }
  topology_changed_ = rep.split.edges_cut > 0 || rep.split.triangles_added != 0;
  return rep.changed();
}

bool CutRegion::place(const Vec3& p_m, const DeformedMesh& mesh) {
  (void)p_m;
  (void)mesh;
  return false;
}

bool CutRegion::follow(const Vec3& p_rest_m, const DeformedMesh& mesh) {
  (void)p_rest_m;
  (void)mesh;
  return false;
}

void CutRegion::after_step() {
  pieces_.push(&*lattice_);
  apply_floor(&*lattice_, floor_z_m_);
  contact_.apply(&*lattice_, grid_);
  pieces_.pull(*lattice_);
}

void CutRegion::deform(std::vector<Vec3>* vertices_m) {
  // the vertices of what moved (the pieces cut free) and of what the cuts changed, not the whole mesh
  frame_deformed_ += cut_.deform_changed(*lattice_, vertices_m);
}

void CutRegion::update_normals(bool moved, const DeformedMesh& mesh) {
  (void)moved;
  // the normals around the vertices moved and the triangles split since the last frame
  frame_normals_ += cut_.update_normals(*mesh.vertices_m, mesh.normals);
}

void CutRegion::patch_candidates(const HapticSample& latest, const std::vector<Vec3>& vertices_m, const Vec3& lo_m,
                                 const Vec3& hi_m, double margin_m, std::vector<int32_t>* out) const {
  // the whole blade edge, whose triangles are not in the grid's leaf lists once split
  const Vec3 end = latest.tool_pos_m + scene_.blade_length_m * latest.blade_axis;
  cut_.triangles_in_box(vertices_m, lo_m.cwiseMin(end - Vec3::Constant(margin_m)),
                        hi_m.cwiseMax(end + Vec3::Constant(margin_m)), out);
}

Vec3 CutRegion::patch_edge(const HapticSample& latest) const { return scene_.blade_length_m * latest.blade_axis; }

void CutRegion::fill_view(const HapticSample& latest, FrameView* view) const {
  // what moved or was cut since the layer was drawn; the triangles change only there
  if (redraw_) {
    view->moving_vertices = &redraw_->moving_vertices();
    view->layer_epoch = redraw_->layer_epoch();
    view->topology_epoch = redraw_->topology_epoch();
    view->static_part_kept = true;
  }
  // displacement from each vertex's own rest (a cut's vertices have theirs); the cut's faces in their colour
  view->rest_m = &cut_.rest_vertices_m();
  view->first_cut_vertex = uncut_vertices_;
  view->show_blade = true;
  view->blade_tip_m = latest.tool_pos_m;
  view->blade_end_m = latest.tool_pos_m + scene_.blade_length_m * latest.blade_axis;
}

void CutRegion::end_frame(double sim_ms) {
  if (redraw_)
    redraw_->update(*lattice_, cut_, blade_cutting_, blade_tip_m_, blade_end_m_, topology_changed_, first_new_);
  if (cutting_) stats_->cutting_ms.push_back(sim_ms);
  else if (stats_->frames_cutting > 0) stats_->after_cut_ms.push_back(sim_ms);
  if (stats_->frames_cutting > 0) {
    stats_->cut_vertices_deformed.push_back(static_cast<double>(frame_deformed_));
    stats_->cut_normals.push_back(static_cast<double>(frame_normals_));
  }
  frame_deformed_ = 0;
  frame_normals_ = 0;
}

}  // namespace palpate
