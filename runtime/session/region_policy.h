#pragma once
/// RegionPolicy: which part of the object the frame stage's lattice covers and how that part changes with the
/// interaction. Touch and pull use a LocalRegion (local_region.h): a block of cells placed around the first
/// contact and moved when the contact leaves it. Cut uses a CutRegion (cut_region.h): one lattice over the whole
/// object, built up front and never moved, whose springs and mesh the blade cuts. The frame stage picks one from
/// the scene's interaction mode (make_region_policy, region_policy_factory.h) and calls it wherever the modes differ.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/scene.h"
#include "core/types.h"
#include "haptics/servo/haptic_sample.h"
#include "render/renderer.h"
#include "sim/cut/cut_model.h"
#include "sim/lattice/lattice.h"
#include "runtime/session/frame_stats.h"
#include "runtime/session/model.h"

namespace palpate {

/// The mesh the lattice deforms: current vertex positions and normals (both n_v; normals may be empty until
/// first computed). Owned by the frame stage, changed by the policy.
struct DeformedMesh {
  std::vector<Vec3>* vertices_m = nullptr;  ///< current positions
  std::vector<Vec3>* normals = nullptr;     ///< current vertex normals
};

/// The lattice region of a recording and what depends on its shape. Holds the lattice; records its figures in
/// the FrameStats it was given (which must outlive it). Not copyable. Thread: the sim thread only.
class RegionPolicy {
 public:
  virtual ~RegionPolicy() = default;
  RegionPolicy(const RegionPolicy&) = delete;
  RegionPolicy& operator=(const RegionPolicy&) = delete;

  /// The lattice, once placed.
  const std::optional<Lattice>& lattice() const { return lattice_; }
  /// The same, to step (null before it is placed).
  Lattice* mutable_lattice() { return lattice_ ? &*lattice_ : nullptr; }
  /// The lattice a frame steps: lattice() itself, or the part of it that moves, kept by the region and written back
  /// in after_step() (cut mode: the pieces cut free); null when no part moves. It takes no contact force when it is
  /// not lattice().
  virtual Lattice* stepped_lattice() { return mutable_lattice(); }

  /// The triangles drawn and touched (the cut mesh's in cut mode, else the model's).
  virtual const std::vector<std::array<int32_t, 3>>& triangles() const = 0;
  /// The cut mesh and its side binding (CutRegion only), else null.
  virtual const CutModel* cut_model() const { return nullptr; }
  /// Mesh vertices deform() writes: those the region's deformer binds, in cut mode every vertex of the cut mesh
  /// (summed into FrameStats::vertex_frames per stepped frame).
  virtual std::size_t bound_vertices() const = 0;
  /// True when the lattice exists from the start and its solver should be prepared before the first frame and
  /// again when the step length changes (a large lattice whose factorisation must not land on a frame deadline).
  virtual bool prepared_ahead() const = 0;

  /// One servo sample, as drained (in order).
  virtual void add_sample(const HapticSample& s) { (void)s; }
  /// After the frame's samples are drained, before the lattice is placed or stepped: applies what the samples
  /// asked of the region's shape. True when the lattice or mesh changed so the lattice must step again.
  virtual bool begin_frame(const DeformedMesh& mesh) {
    (void)mesh;
    return false;
  }
  /// Places the region around the surface point p_m if it has no lattice yet. True when a lattice was built.
  virtual bool place(const Vec3& p_m, const DeformedMesh& mesh) = 0;
  /// This frame's contact lies at the material point p_rest_m (rest coordinates): re-places the region when the
  /// contact left it (state carried over). True when the lattice was rebuilt.
  virtual bool follow(const Vec3& p_rest_m, const DeformedMesh& mesh) = 0;
  /// After a step that moved the lattice: the region's own constraints.
  virtual void after_step() {}
  /// Moves the mesh vertices with the lattice.
  virtual void deform(std::vector<Vec3>* vertices_m) = 0;
  /// Recomputes the normals that can have changed this frame (moved: the lattice was stepped).
  virtual void update_normals(bool moved, const DeformedMesh& mesh) = 0;
  /// Ids of the triangles the servo's patch is chosen from: those near the box [lo_m, hi_m] around the tool
  /// and proxy of `latest` (margin_m: how far the box was grown around them).
  virtual void patch_candidates(const HapticSample& latest, const std::vector<Vec3>& vertices_m, const Vec3& lo_m,
                                const Vec3& hi_m, double margin_m, std::vector<int32_t>* out) const = 0;
  /// The segment from the tool that the patch's nearest-first order measures distance to (zero: the tool point).
  virtual Vec3 patch_edge(const HapticSample& latest) const {
    (void)latest;
    return Vec3::Zero();
  }
  /// Fills what the view shows of the region: which vertices may move (the renderer's cached layer), the blade.
  virtual void fill_view(const HapticSample& latest, FrameView* view) const = 0;
  /// A frame budget runs: a cut takes at most n springs out of the lattice a frame, the rest on the frames after
  /// (each costs the solver a factor downdate before the step). No effect where nothing is cut.
  virtual void limit_springs_cut_per_frame(int n) { (void)n; }
  /// The frame ended; sim_ms is its cost.
  virtual void end_frame(double sim_ms) { (void)sim_ms; }

 protected:
  RegionPolicy() = default;
  std::optional<Lattice> lattice_;
};

}  // namespace palpate
