#include "runtime/session/local_region.h"

#include <algorithm>
#include <cstdlib>

#include "core/tri_mesh.h"
#include "core/vertex_triangles.h"
#include "sim/lattice/refined_lattice.h"
#include "sim/lattice/region.h"
#include "sim/material/strain.h"

namespace palpate {

LocalRegion::LocalRegion(const Scene& scene, const Model& model, FrameStats* stats)
    : scene_(scene), model_(model), stats_(stats) {}

bool LocalRegion::place(const Vec3& p_m, const DeformedMesh& mesh) {
  if (lattice_) return false;
  return build_at(p_m, mesh, true);
}

bool LocalRegion::follow(const Vec3& p_rest_m, const DeformedMesh& mesh) {
  if (!lattice_ || !scene_.lattice.follow_contact) return false;
  // the material point's cell is where the contact force goes: it must be inside the region, off its fixed ring
  const int level = scene_.lattice.level;
  const CellCoord cell = model_.grid.cell_of(p_rest_m, level);
  const RefineSpec& refine = scene_.lattice.refine;
  if (refine.level > 0) {
    // refined: the coarse region moves as a uniform one would; the fine zone moves with the contact, once it is
    // half the zone's radius from where the zone was built
    const int d = std::max({std::abs(cell.i - center_.i), std::abs(cell.j - center_.j), std::abs(cell.k - center_.k)});
    const int32_t fine = model_.grid.linear_index(model_.grid.cell_of(p_rest_m, lattice_->level), lattice_->level);
    const bool leaves = d >= scene_.lattice.radius_cells || lattice_->slot_of_cell[static_cast<std::size_t>(fine)] < 0;
    if (!leaves && (p_rest_m - zone_center_m_).norm() <= 0.5 * refine.radius_m) return false;
    return build_at(p_rest_m, mesh, leaves);
  }
  if (!contact_leaves_region(*lattice_, center_, cell, scene_.lattice.radius_cells)) return false;
  return build_at(p_rest_m, mesh, true);
}

bool LocalRegion::build_at(const Vec3& p_m, const DeformedMesh& mesh, bool recentre) {
  const int level = scene_.lattice.level;
  const CellCoord center = recentre || !lattice_ ? model_.grid.cell_of(p_m, level) : center_;
  const int radius = scene_.lattice.radius_cells;
  const RefineSpec& refine = scene_.lattice.refine;
  Result<Lattice> lat = make_error("no lattice");
  if (refine.level > 0) {
    // the coarse cells around the contact and those still deformed; those near the contact split a level at a time
    std::vector<int32_t> cells = region_cells(model_.grid, level, center, radius);
    if (lattice_) {
      const auto kept = deformed_coarse_cells(model_.grid, *lattice_, level, 1e-3 * lattice_->cell_m);
      cells.insert(cells.end(), kept.begin(), kept.end());
      std::sort(cells.begin(), cells.end());
      cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    }
    lat = build_refined_lattice(model_.grid, scene_.lattice, cells, refine.level,
                                graded_leaves(model_.grid, level, cells, refine.level, p_m, refine.radius_m));
  } else {
    // a moved region keeps the old cells that are still deformed (beyond 1e-3 of a cell), so nothing snaps back
    lat = build_lattice(model_.grid, scene_.lattice,
                        lattice_ ? followed_region_cells(model_.grid, *lattice_, center, radius, 1e-3 * lattice_->cell_m)
                                 : region_cells(model_.grid, level, center, radius));
  }
  if (!lat) return false;  // no solid cell near the contact: nothing to deform
  std::vector<Vec3>& vertices_m = *mesh.vertices_m;
  if (lattice_) {
    if (refine.level > 0) carry_state_refined(model_.grid, *lattice_, &lat.value());
    else carry_state(*lattice_, &lat.value());
    // vertices of dropped cells go back to rest; the others are deformed again by the new lattice. Normals
    // that depended on the old region are final now unless they depend on the new one (redone after deform).
    for (int32_t v : deformer_.vertex_ids()) vertices_m[v] = model_.rest.vertices_m[v];
    if (!strain_.empty())
      for (int32_t v : deformer_.vertex_ids()) strain_[static_cast<std::size_t>(v)] = 0.0f;
    if (!mesh.normals->empty()) normal_patch_.update(vertices_m, triangles(), mesh.normals);
    ++stats_->region_moves;
  }
  lattice_ = std::move(lat).value();
  center_ = center;
  zone_center_m_ = p_m;
  deformer_.attach(*lattice_, model_.bindings);
  normal_dependents(triangles(), model_.adjacency, deformer_.vertex_ids(), &mark_scratch_, &normal_ids_);
  normal_patch_.attach(model_.adjacency, normal_ids_);
  changed_ = true;
  ++layer_epoch_;
  stats_->lattice_nodes = std::max(stats_->lattice_nodes, lattice_->num_nodes());
  stats_->lattice_springs = std::max(stats_->lattice_springs, lattice_->springs.size());
  stats_->lattice_vertices = std::max(stats_->lattice_vertices, deformer_.num_bound_vertices());
  return true;
}

void LocalRegion::deform(std::vector<Vec3>* vertices_m) {
  deformer_.deform(*lattice_, model_.bindings, model_.rest.vertices_m, vertices_m);
  if (!colors_by_strain(scene_)) return;
  // the frame's strain, from the nodes of the cells it deformed to the vertices they carry
  if (strain_.size() != vertices_m->size()) strain_.assign(vertices_m->size(), 0.0f);
  node_equivalent_strain(*lattice_, &node_strain_, &strain_count_);
  deformer_.interpolate(*lattice_, model_.bindings, model_.rest.vertices_m, node_strain_, &strain_);
}

void LocalRegion::update_normals(bool moved, const DeformedMesh& mesh) {
  // only the normals of the region's vertices and their neighbours can change
  if (mesh.normals->empty()) compute_vertex_normals(*mesh.vertices_m, triangles(), mesh.normals);
  else if (moved || changed_) normal_patch_.update(*mesh.vertices_m, triangles(), mesh.normals);
  changed_ = false;
}

void LocalRegion::patch_candidates(const HapticSample& latest, const std::vector<Vec3>& vertices_m, const Vec3& lo_m,
                                   const Vec3& hi_m, double margin_m, std::vector<int32_t>* out) const {
  (void)latest;
  (void)vertices_m;
  (void)margin_m;
  model_.grid.triangles_near(lo_m, hi_m, out, &near_scratch_);
}

void LocalRegion::fill_view(const HapticSample& latest, FrameView* view) const {
  (void)latest;
  view->moving_vertices = &deformer_.vertex_ids();
  view->layer_epoch = layer_epoch_;
  view->rest_m = &model_.rest.vertices_m;
  if (colors_by_strain(scene_) && !strain_.empty()) view->vertex_value = &strain_;
}

}  // namespace palpate
