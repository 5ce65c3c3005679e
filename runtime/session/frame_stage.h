#pragma once
/// FrameStage: the per-frame work (scene.rates.frame_hz) — drain servo samples, load and step the lattice, deform the mesh,
/// publish the surface patch for the servo, render and queue the PNG.

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
#include "sim/contact_compliance.h"
#include "sim/contact_load.h"
#include "sim/contact_response.h"
#include "haptics/haptic_sample.h"
#include "haptics/local_model.h"
#include "render/gl_context.h"
#include "render/mesh_lod.h"
#include "render/png_writer.h"
#include "render/renderer.h"
#include "render/video_writer.h"
#include "sim/cut_model.h"
#include "sim/frame_budget.h"
#include "sim/integrator.h"
#include "sim/lattice.h"
#include "sim/solved_contact.h"
#include "runtime/session/frame_stats.h"
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
  void set_video(VideoWriter* video) { video_ = video; }
  /// Also publishes every frame's pixels, samples and figures to a live view (may be null; must outlive the
  /// stage); it never waits for the view's readers.
  void set_live(LiveFeed* live) { live_ = live; }
  /// Keeps the scene's lattice.budget_ms with the frame's sim cost read from `clock` (must outlive the stage):
  /// each frame steps at the most accurate setting of the ladder predicted to hold the budget. No effect when
  /// the scene sets no budget or its integrator has nothing to trade.
  void use_budget(BudgetClock* clock);
  /// Realtime: every frame's lattice step has a deadline a frame period after the frame starts (on the monotonic
  /// clock): an implicit substep that failed whole is retried (splits, projected Newton) only until then, and the
  /// frame goes on with the state the step reached (StepOptions::deadline_ns). Lockstep frames have none.
  void keep_deadlines() { deadlines_ = true; }
  /// The budget controller, when one runs.
  const FrameBudget* budget() const { return budget_ ? &*budget_ : nullptr; }
  /// What a realtime run does before its clock starts, so the first frame's deadline does not pay for one-time
  /// costs: draws the current state once without writing it anywhere (the GL driver compiles its shaders on the
  /// first draw: tens of ms; frames drawn afterwards are the same pixels), and with a budget and a lattice,
  /// times one step of a copy of the lattice to seed the budget (FrameBudget::seed_step; the run's own state is
  /// untouched). Call use_budget() first.
  void warm_up();
  /// Drains and logs samples left after the last frame.
  void drain_remaining();
  /// 16-hex-digit hash of lattice state and deformed mesh.
  std::string state_hash() const;
  /// Collected figures.
  const FrameStats& stats() const { return stats_; }
  /// The frames' colours, arrow and legend (the colours' range as it ended).
  const ViewStyle& view_style() const { return style_; }
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
  // a frame the servo sent nothing to (a realtime servo stalled) keeps the last frame's contact and mean force, rather
  // than letting go of the surface for the frame (a pull shaken through the browser sprang back during a 100 ms
  // servo stall, and the hand met it with a 0.6 N step when the servo came back)
  void keep_contact_through_silence();
  // places the region at this frame's first contact
  void place_region();
  // moves the region when this frame's contact left it (state carried over)
  void follow_contact();
  // the lattice is new or changed: it steps again, and the node forces fit it
  void region_changed();
  // steps the lattice unless it rests; true when it moved
  bool step_lattice_frame();
  // the frame's contact force on the lattice nodes; returns how many nodes it went to
  int apply_contact_force(std::vector<Vec3>* f_ext);
  // the contact of sample s as the contact load reads it (sim/contact_load.h), with the scene's tool
  ToolContact tool_contact(const HapticSample& s) const;
  // the object's linearised response at the current contact (sim/contact_response.h), for the servo between frames
  void fill_contact_model(LocalModel* m);
  // the estimated compliance at w where the servo needs it (a point tool on a surface far softer than the coupling)
  std::optional<Mat3> needed_estimate(const Lattice& lat, const PointWeights& w);
  void publish_patch();
  // counts a frame whose free tool (touch mode) lies deeper inside the object than the material can have moved: every
  // point of the object is at most the lattice's largest displacement from where it rests, so a point deeper than
  // that (and the tool's radius) under the rest surface is inside the deformed object, whatever the dent (never a
  // false alarm). The tool went through the surface, or began inside.
  void check_tool_inside();
  // counts a drained tick whose free tool, or held proxy, lies inside the object beyond what the material has moved
  // (the last deform's largest node displacement) and the tool's radius: the god-object's invariant broken
  void check_through(const HapticSample& s);
  void render(int64_t index, bool block);
  // files the time since the last part ended under `part` of the frame's profile
  void lap(FramePart part);

  const Scene& scene_;
  const Model& model_;
  const RestObject rest_;            // the model at rest, as the contact load reads it
  SpscQueue<HapticSample>* samples_;
  TripleBuffer<LocalModel>* local_model_;
  Renderer* renderer_;
  PngWriter* writer_;
  VideoWriter* video_ = nullptr;
  LiveFeed* live_ = nullptr;
  HapticLog* log_;

  FrameStats stats_;                 // (before region_, which records into it)
  std::unique_ptr<RegionPolicy> region_;  // the lattice region of the scene's interaction mode
  IntegratorWorkspace ws_;
  StepOptions step_opts_;            // from the scene, fixed for the run
  std::optional<FrameBudget> budget_;  // lattice.budget_ms: picks the step options of each frame
  const StepOptions* frame_opts_ = nullptr;  // this frame's options (the budget's), else step_opts_
  ThreadCpuClock cpu_clock_;         // for the CPU-time figures
  bool resting_ = false;             // the lattice is at rest: not stepped until a force acts
  std::vector<Vec3> rest_scratch_;   // forces for the rest check (n)
  std::vector<Vec3> f_ext_N_;        // external node forces (n)
  std::vector<Vec3> part_f_ext_N_;   // zero forces on the stepped part of the lattice, when not all of it (n_part)
  std::vector<Vec3> vertices_m_;     // deformed mesh (n_v)
  ViewStyle style_;                  // the frames' colours, force arrow and legend
  double drawn_peak_N_ = -1.0;       // the largest force a tick sent since the last frame drawn (-1: no tick)
  struct PublishedCorners {
    std::array<Vec3, 3> corners, normals;
  };
  std::unordered_map<int32_t, PublishedCorners> published_;  // the last patch's corners and shading normals by id
  std::vector<Vec3> normals_;        // per vertex (n_v)
  std::vector<uint8_t> warm_rgba_;   // warm_up()'s frame, never written (w * h * 4)
  std::optional<MeshLod> lod_;       // what frames are drawn with when the mesh is finer than the image
  bool dry_stepped_ = false;         // warm_up() seeded the budget
  bool deadlines_ = false;           // keep_deadlines(): realtime frames' steps end at a deadline
  int64_t frame_start_ns_ = 0;       // when the current frame started (monotonic)
  std::vector<int32_t> near_tris_;   // scratch for the patch query
  std::vector<std::pair<double, int32_t>> near_keys_;  // scratch: (distance, triangle) of a truncated patch
  ContactCompliance compliance_;     // static condensation of the lattice at the contact
  std::vector<double> estimate_scratch_;  // per-node storage of the estimated compliance (sim/compliance_estimate.h)
  SolvedContactLoad solved_;         // device.contact "solved": the push's weights from the contact
  PointWeights solved_w_;            // those of this frame (valid while solved_this_frame_)
  bool solved_this_frame_ = false;
  bool compliance_next_frame_ = false;  // the region was placed or moved this frame: no contact model until the next
  Vec3 frame_force_obj_N_ = Vec3::Zero();  // force pushed on the object during the last step
  double t_s_ = 0.0;                 // scene time of the current frame
  int64_t frame_index_ = -1;         // index of the current frame (the patch it publishes carries it)
  HapticSample latest_;              // newest sample drained
  HapticSample contact_;             // newest sample in contact this frame
  bool contact_this_frame_ = false;
  Vec3 force_sum_N_ = Vec3::Zero();  // sum of device forces over the frame's samples
  int64_t frame_samples_ = 0;
  Vec3 last_mean_force_N_ = Vec3::Zero();  // the mean device force of the last frame that had samples
  double lattice_moved_m_ = 0.0;  // the lattice's largest node displacement after the last step (check_through)
  Vec3 through_at_m_ = Vec3::Zero();  // where check_through last asked, and how far from it its answer still holds
  double through_still_m_ = 0.0;
  FrameProfile profile_;             // the current frame's parts
  std::chrono::steady_clock::time_point lap_wall_;  // end of the last part timed
  double lap_cpu_ms_ = 0.0;
};

}  // namespace palpate
