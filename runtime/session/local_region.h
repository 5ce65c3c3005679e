#pragma once
/// LocalRegion (touch, pull): a block of lattice cells around the contact, built at the first contact and moved
/// when the contact leaves it, keeping the cells that are still deformed and carrying their state over.

#include <cstdint>
#include <vector>

#include "core/grid_hierarchy.h"
#include "core/vertex_triangles.h"
#include "sim/lattice/deformer.h"
#include "runtime/session/region_policy.h"

namespace palpate {

/// The region of lattice.radius_cells around the contact cell at lattice.level; only the vertices bound to it
/// move, so only their normals and those of their neighbours are recomputed, and the renderer draws the rest
/// once into its cached layer.
class LocalRegion final : public RegionPolicy {
 public:
  /// scene, model and stats must outlive the region. No lattice until place().
  LocalRegion(const Scene& scene, const Model& model, FrameStats* stats);

  const std::vector<std::array<int32_t, 3>>& triangles() const override { return model_.rest.triangles; }
  std::size_t bound_vertices() const override { return deformer_.num_bound_vertices(); }
  bool prepared_ahead() const override { return false; }
  bool place(const Vec3& p_m, const DeformedMesh& mesh) override;
  bool follow(const Vec3& p_rest_m, const DeformedMesh& mesh) override;
  void deform(std::vector<Vec3>* vertices_m) override;
  void update_normals(bool moved, const DeformedMesh& mesh) override;
  void patch_candidates(const HapticSample& latest, const std::vector<Vec3>& vertices_m, const Vec3& lo_m,
                        const Vec3& hi_m, double margin_m, std::vector<int32_t>* out) const override;
  void fill_view(const HapticSample& latest, FrameView* view) const override;

  /// The contact cell the region was last built around.
  const CellCoord& center() const { return center_; }

 private:
  // builds the region around p_m (a moved one keeps the old cells still deformed and their state); recentre: the
  // coarse region's centre moves to p_m too (else only a refined lattice's fine zone does)
  bool build_at(const Vec3& p_m, const DeformedMesh& mesh, bool recentre);

  const Scene& scene_;
  const Model& model_;
  FrameStats* stats_;
  MeshDeformer deformer_;
  // render.color 'strain': each vertex's equivalent strain (n_v once colouring starts; 0 off the region), and
  // the nodes' (scratch)
  std::vector<float> strain_;
  std::vector<double> node_strain_;
  std::vector<int> strain_count_;
  CellCoord center_;                  // contact cell the region was built around
  Vec3 zone_center_m_ = Vec3::Zero(); // refined lattice: the contact point its fine zone was built around
  std::vector<int32_t> normal_ids_;   // vertices whose normal the region can change
  VertexNormalPatch normal_patch_;    // recomputes their normals, each face normal once
  mutable std::vector<int32_t> near_scratch_;  // the patch query's sort buffer (grow-only; sim thread only)
  std::vector<uint8_t> mark_scratch_; // scratch for normal_dependents (n_v)
  bool changed_ = false;              // the region was (re)built this frame: its normals are due
  uint64_t layer_epoch_ = 0;          // bumped when the moving vertices change (the renderer's cached layer)
};

}  // namespace palpate
