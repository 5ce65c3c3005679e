#pragma once
/// CutRegion (cut): one lattice over every solid cell of the object, built with the region and never moved (the
/// blade may go anywhere and cuts must persist). The blade's sweeps cut its springs and split the mesh, at most
/// kCutWorkPerFrame triangles and vertices near the sweep tested a frame (the rest of a long stroke on the frames after);
/// pieces cut free fall onto the body (sim/contact/piece_contact.h) or a floor at the lowest node plane. The body keeps its
/// rest shape: only the pieces cut free are stepped (sim/cut/cut_pieces.h).

#include <cstdint>
#include <optional>
#include <vector>

#include "sim/cut/cut_model.h"
#include "sim/cut/cut_pieces.h"
#include "sim/contact/piece_contact.h"
#include "runtime/session/cut_redraw.h"
#include "runtime/session/region_policy.h"

namespace palpate {

/// Triangles the mesh split tests plus vertices the side binding tests a frame, at most (one rest quad's more when
/// a single quad reaches more; CutModel::set_max_cut_work_per_apply).
inline constexpr int kCutWorkPerFrame = 8000;

/// The whole-object region. Its node count never changes: a cut removes springs, and the nodes of a piece cut
/// free of every fixed node stay in the lattice (counted in FrameStats::free_nodes). The object starts at rest in
/// its own shape, taken as resting under gravity already (no static solve: the first frame does not wait); the
/// renderer redraws only the part that moved or was cut (cut_redraw.h).
class CutRegion final : public RegionPolicy {
 public:
  /// Builds the whole-object lattice and the uncut mesh's side binding. scene, model and stats must outlive
  /// the region. No lattice when the object has no solid cell at lattice.level.
  CutRegion(const Scene& scene, const Model& model, FrameStats* stats);

  const std::vector<std::array<int32_t, 3>>& triangles() const override { return cut_.triangles(); }
  const CutModel* cut_model() const override { return &cut_; }
  void limit_springs_cut_per_frame(int n) override { cut_.set_max_springs_per_apply(n); }
  /// Every vertex of the cut mesh, as it stands after this frame's splits: the side binding binds them all and
  /// deform() writes them all.
  std::size_t bound_vertices() const override { return cut_.rest_vertices_m().size(); }
  /// The whole-object lattice is never stepped (only its pieces, each factored when it comes free).
  bool prepared_ahead() const override { return false; }
  /// The pieces cut free, null while there are none.
  Lattice* stepped_lattice() override { return pieces_.empty() ? nullptr : &pieces_.lattice(); }
  /// Records the blade of each sample: it cuts what it sweeps while the button is held and the reading was
  /// accepted.
  void add_sample(const HapticSample& s) override;
  /// Applies the blade sweeps recorded since the last frame (springs cut, mesh split, *mesh.vertices_m grown). True
  /// when anything changed.
  bool begin_frame(const DeformedMesh& mesh) override;
  /// The whole-object lattice is never placed anew.
  bool place(const Vec3& p_m, const DeformedMesh& mesh) override;
  /// The whole-object lattice never follows the contact.
  bool follow(const Vec3& p_rest_m, const DeformedMesh& mesh) override;
  /// Writes the stepped pieces into the whole lattice and keeps them on the floor and out of the body.
  void after_step() override;
  /// Moves the vertices that can have changed since the last call (CutModel::deform_changed), not the whole mesh.
  void deform(std::vector<Vec3>* vertices_m) override;
  /// Recomputes the normals around what moved or was split since the last call (CutModel::update_normals).
  void update_normals(bool moved, const DeformedMesh& mesh) override;
  void patch_candidates(const HapticSample& latest, const std::vector<Vec3>& vertices_m, const Vec3& lo_m,
                        const Vec3& hi_m, double margin_m, std::vector<int32_t>* out) const override;
  /// The blade edge, so the triangles it crosses are kept first.
  Vec3 patch_edge(const HapticSample& latest) const override;
  void fill_view(const HapticSample& latest, FrameView* view) const override;
  /// Files the frame's cost under cutting_ms (it cut) or after_cut_ms (a later frame that did not).
  void end_frame(double sim_ms) override;

  /// The floor height for pieces cut free: the lowest node plane.
  double floor_z_m() const { return floor_z_m_; }

 private:
  const Scene& scene_;
  const GridHierarchy& grid_;
  FrameStats* stats_;
  PieceContact contact_;     // pieces cut free against the body
  PieceLattice pieces_;      // the pieces cut free, stepped on their own
  CutModel cut_;             // the cut mesh and side binding
  double floor_z_m_ = 0.0;   // lowest node plane
  bool cutting_ = false;     // this frame applied blade sweeps
  std::optional<CutRedraw> redraw_;  // what frames may move, for the renderer's layer
  bool blade_cutting_ = false;       // the last sample's button was held
  Vec3 blade_tip_m_ = Vec3::Zero(), blade_end_m_ = Vec3::Zero();  // the last sample's blade edge
  bool topology_changed_ = false;    // this frame's split changed the triangles
  std::size_t first_new_ = 0;        // first vertex this frame's split created
  std::size_t frame_deformed_ = 0;   // mesh vertices deform() recomputed this frame
  std::size_t frame_normals_ = 0;    // vertex normals recomputed this frame
  int64_t uncut_vertices_ = 0;       // the model's own vertices (the cut's come after them)
};

}  // namespace palpate
