#pragma once
/// FrameStage: the order of the per-frame work (scene.rates.frame_hz), each part a unit of its own: drain the servo's
/// samples (ContactFeed, ThroughWatch), place the region, load the lattice (LatticeContact) and step it
/// (LatticeStepper), deform the mesh and its normals (the region policy), publish the surface patch and the contact
/// model to the servo, and draw the frame (FrameOutputs).

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/scene.h"
#include "core/spsc_queue.h"
#include "core/triple_buffer.h"
#include "core/vertex_triangles.h"
#include "sim/contact/contact_compliance.h"
#include "sim/contact/contact_load.h"
#include "sim/contact/contact_response.h"
#include "haptics/servo/haptic_sample.h"
#include "haptics/servo/local_model.h"
#include "render/gl_context.h"
#include "render/mesh_lod.h"
#include "render/png_writer.h"
#include "render/renderer.h"
#include "render/video_writer.h"
#include "sim/cut/cut_model.h"
#include "sim/solvers/frame_budget.h"
#include "sim/solvers/integrator.h"
#include "sim/lattice/lattice.h"
#include "sim/contact/solved_contact.h"
#include "runtime/session/frame_outputs.h"
#include "runtime/session/frame_stats.h"
#include "runtime/session/lattice_contact.h"
#include "runtime/session/lattice_stepper.h"
#include "runtime/session/through_watch.h"
#include "runtime/session/haptic_log.h"
#include "runtime/live/live_feed.h"
#include "runtime/session/model.h"
#include "runtime/session/region_policy.h"
#include "runtime/session/view_style.h"

namespace palpate {

/// Owns the region policy (and through it the lattice), the deformed mesh and the render state of one
/// recording; the policy, chosen from the scene's interaction mode, does what differs between a local region
/// (touch, pull) and the whole-object region the blade cuts (cut). Thread: the sim thread only.
class FrameStage {
 public:
  /// All pointers must outlive the stage. renderer / writer may be null (no rendering).
  FrameStage(const Scene& scene, const Model& model, SpscQueue<HapticSample>* samples,
             TripleBuffer<LocalModel>* local_model, Renderer* renderer, PngWriter* writer, HapticLog* log);

  /// Processes frame `index` at scene time t_s; block_on_writer waits for a free PNG buffer (lockstep)
  /// instead of dropping the frame (realtime). The frame takes the servo's samples up to tick drain_to_tick (a
  /// replay of a realtime run takes what that run's frame took; by default all there are).
  void frame(int64_t index, double t_s, bool block_on_writer, int64_t drain_to_tick = INT64_MAX);
  /// Also encodes every rendered frame into `video` (may be null; must outlive the stage); it gets the same
  /// pixels as the PNG writer, waiting for the encoder when frame() blocks on the writer, else dropping.
  void set_video(VideoWriter* video) { outputs_.set_video(video); }
  /// Also publishes every frame's pixels, samples and figures to a live view (may be null; must outlive the
  /// stage); it never waits for the view's readers.
  void set_live(LiveFeed* live) { outputs_.set_live(live); }
  /// Keeps the scene's lattice.budget_ms with the frame's sim cost read from `clock` (must outlive the stage):
  /// each frame steps at the most accurate setting of the ladder predicted to hold the budget. No effect when
  /// the scene sets no budget or its integrator has nothing to trade.
  void use_budget(BudgetClock* clock);
  /// Realtime: every frame's lattice step has a deadline a frame period after the frame starts (on the monotonic
  /// clock): an implicit substep that failed whole is retried (splits, projected Newton) only until then, and the
  /// frame goes on with the state the step reached (StepOptions::deadline_ns). Lockstep frames have none.
  void keep_deadlines() { stepper_.keep_deadlines(); }
  /// The budget controller, when one runs.
  const FrameBudget* budget() const { return stepper_.budget(); }
  /// What a realtime run does before its clock starts, so the first frame's deadline does not pay for one-time
  /// costs: draws the current state once without writing it anywhere (the GL driver compiles its shaders on the
  /// first draw: tens of ms; frames drawn afterwards are the same pixels), and with a budget and a lattice,
  /// times one step of a copy of the lattice to seed the budget (FrameBudget::seed_step; the run's own state is
  /// untouched). Call use_budget() first.
  void warm_up();
  /// Drains and logs samples left after the last frame.
  void drain_remaining();
  /// The controls the newest sample taken was made under (seq 0: the scene's own).
  const Controls& latest_controls() const { return feed_.latest().controls; }
  /// The controls this stage runs under: its patches carry their seq (LocalModel::controls_seq), so a servo under
  /// other controls feels none of them. Before the first frame.
  void set_controls_seq(int64_t seq) { controls_seq_ = seq; }
  /// Takes over the figures of the stage this one follows (a restart under new controls). Before the first frame.
  void adopt_stats(FrameStats&& earlier) { stats_ = std::move(earlier); }
  /// 16-hex-digit hash of lattice state and deformed mesh.
  std::string state_hash() const;
  /// Collected figures.
  const FrameStats& stats() const { return stats_; }
  /// The frames' colours, arrow and legend (the colours' range as it ended).
  const ViewStyle& view_style() const { return outputs_.style(); }
  /// Current deformed vertex positions.
  const std::vector<Vec3>& vertices_m() const { return vertices_m_; }
  /// Current vertex normals (those the region can change are recomputed each frame, the rest kept).
  const std::vector<Vec3>& normals() const { return normals_; }
  /// The lattice: a local region once a contact has built it; in cut mode the whole object from the start.
  const std::optional<Lattice>& lattice() const { return region_->lattice(); }
  /// The triangles drawn and touched: the cut mesh in cut mode, else the model's.
  const std::vector<std::array<int32_t, 3>>& triangles() const { return region_->triangles(); }
  /// The cut mesh and its side binding (cut mode only, else null).
  const CutModel* cut_model() const { return region_->cut_model(); }
  /// The clustered triangles frames are drawn with when the mesh is finer than the image
  /// (render.lod_min_edge_px), else null.
  const MeshLod* lod() const { return lod_ ? &*lod_ : nullptr; }
  /// What a frame drawn now shows (pointers into the stage, valid until its next frame).
  FrameView current_view() const;

 private:
  // takes the queued samples up to tick drain_to_tick, marked as taken by `frame`, into the log and the region
  void drain(int64_t frame, int64_t drain_to_tick);
  // places the region at this frame's first contact
  void place_region();
  // moves the region when this frame's contact left it (state carried over)
  void follow_contact();
  // the lattice is new or changed: it steps again, and the node forces fit it; wait: the servo's contact model waits
  // a frame (the region was placed or moved this frame)
  void region_changed(bool wait = false);
  void publish_patch();
  void render(int64_t index, bool block);
  // files the time since the last part ended under `part` of the frame's profile
  void lap(FramePart part);

  const Scene& scene_;
  const Model& model_;
  const RestObject rest_;            // the model at rest, as the contact load reads it
  SpscQueue<HapticSample>* samples_;
  TripleBuffer<LocalModel>* local_model_;
  HapticLog* log_;

  FrameStats stats_;                 // (before the units that record into it)
  FrameOutputs outputs_;             // where a drawn frame goes, and its look
  LatticeContact lattice_contact_;   // the hand's force onto the lattice, the lattice's response to the servo
  ThroughWatch through_;             // the god-object's invariant, counted
  ContactFeed feed_;                 // the frame's samples: the newest, the newest in contact, the mean force
  LatticeStepper stepper_;           // the frame's step, within its budget and deadline
  std::unique_ptr<RegionPolicy> region_;  // the lattice region of the scene's interaction mode
  ThreadCpuClock cpu_clock_;         // for the CPU-time figures
  std::vector<Vec3> f_ext_N_;        // external node forces (n)
  std::vector<Vec3> vertices_m_;     // deformed mesh (n_v)
  struct PublishedCorners {
    std::array<Vec3, 3> corners, normals;
  };
  std::unordered_map<int32_t, PublishedCorners> published_;  // the last patch's corners and shading normals by id
  std::vector<Vec3> normals_;        // per vertex (n_v)
  std::optional<MeshLod> lod_;       // what frames are drawn with when the mesh is finer than the image
  std::vector<int32_t> near_tris_;   // scratch for the patch query
  std::vector<std::pair<double, int32_t>> near_keys_;  // scratch: (distance, triangle) of a truncated patch
  double t_s_ = 0.0;                 // scene time of the current frame
  int64_t frame_index_ = -1;         // index of the current frame (the patch it publishes carries it)
  int64_t controls_seq_ = 0;         // the controls it runs under (the patch carries it too)
  double lattice_moved_m_ = 0.0;  // the lattice's largest node displacement after the last step
  FrameProfile profile_;             // the current frame's parts
  std::chrono::steady_clock::time_point lap_wall_;  // end of the last part timed
  double lap_cpu_ms_ = 0.0;
};

}  // namespace palpate
