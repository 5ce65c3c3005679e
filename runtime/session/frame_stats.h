#pragma once
/// FrameStats: the figures the frame stage and its region policy collect over a recording.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace palpate {

/// The parts of a frame's sim work, in frame order.
enum class FramePart : int {
  kDrain,    ///< servo samples drained (and logged)
  kCut,      ///< the blade's sweeps applied: springs cut, mesh split, side binding (topology)
  kLoad,     ///< the contact force spread onto the lattice nodes
  kFactor,   ///< the solver's matrix brought up to date (local/global: downdate or refactorisation)
  kStep,     ///< the step's iterations
  kDeform,   ///< floor, displacement figure, mesh moved with the lattice
  kNormals,  ///< vertex normals
  kPatch,    ///< the servo's surface patch and contact model published
  kCount
};
inline constexpr int kFrameParts = static_cast<int>(FramePart::kCount);
/// Names of the parts as the summary gives them.
inline constexpr const char* kFramePartNames[kFrameParts] = {"drain", "cut",    "load",    "factor",
                                                             "step",  "deform", "normals", "patch"};

/// Where one frame's sim time went: wall and thread CPU ms of each part, the frame's wall and CPU time and the
/// times the CPU was taken from the sim thread during it (wall well above CPU, with switches: preemption, not
/// work). Plain data.
struct FrameProfile {
  int64_t frame = 0;                   ///< scene frame index
  double wall_ms[kFrameParts] = {};    ///< per part, wall clock
  double cpu_ms[kFrameParts] = {};     ///< per part, the sim thread's CPU time
  double frame_wall_ms = 0.0;          ///< the whole sim part of the frame (as sim_ms)
  double frame_cpu_ms = 0.0;           ///< the same in the sim thread's CPU time (as sim_cpu_ms)
  int64_t involuntary_switches = -1;   ///< times the CPU was taken from the sim thread in the frame (-1: unknown)
  int iterations = 0;                  ///< solver iterations the step took (0: not stepped or an explicit scheme)
  int cg_iterations = 0;               ///< implicit Euler: conjugate gradient iterations the step took
  int springs_cut = 0;                 ///< springs the frame's cut removed
};

/// Figures the frame stage collects (read after the run).
struct FrameStats {
  std::vector<double> sim_ms;       ///< per frame: drain + step + deform + publish
  std::vector<double> render_ms;    ///< per rendered frame
  std::vector<double> render_cpu_ms;    ///< per rendered frame: render_ms in the render thread's CPU time
  std::vector<double> layer_build_ms;   ///< per rendered frame that redrew the cached layer: its render_ms
  std::vector<double> layer_build_cpu_ms;  ///< the same frames' render_cpu_ms
  std::vector<double> layer_build_px;   ///< the same frames: pixels of the layer redrawn (Renderer::last_layer_px)
  int64_t frames_layered = 0;       ///< rendered frames that drew only what moves over the cached static layer
  std::vector<int64_t> written_frames; ///< scene frame index of each PNG, in file order (frame_00000 first)
  int64_t frames = 0;               ///< frames processed
  int64_t frames_rendered = 0;      ///< frames handed to the PNG writer
  int64_t frames_dropped = 0;       ///< realtime: frames not rendered because the writer was full
  int64_t nan_events = 0;           ///< lattice states that went non-finite (reset to rest)
  int64_t samples = 0;              ///< servo samples drained
  double max_displacement_m = 0.0;  ///< largest node displacement from rest
  // touch mode: frames whose free tool was inside the object, deeper under its rest surface than the material has
  // moved (FrameStage::check_tool_inside): a touch lost, the tool through the surface
  int64_t tool_inside_frames = 0;
  double tool_inside_first_t_s = -1.0;  ///< the first such frame's time (-1: none)
  double tool_inside_depth_m = 0.0;     ///< how deep under the rest surface it was then, at least
  // touch mode, every servo tick (FrameStage::check_through): the god-object's one invariant broken — a free tool, or
  // a held proxy, deeper under the rest surface than the material has moved plus the tool's radius
  int64_t tool_inside_ticks = 0;        ///< free ticks with the tool inside: a touch missed or lost
  int64_t proxy_inside_ticks = 0;       ///< contact ticks with the proxy inside: the proxy crossed the surface
  double through_first_t_s = -1.0;      ///< the first such tick's time (-1: none)
  int max_substeps = 0;             ///< most substeps in one frame
  double max_strain = 0.0;          ///< largest spring strain |l - l0| / l0 after any step (diverged steps left out)
  std::size_t lattice_nodes = 0, lattice_springs = 0, lattice_vertices = 0;  ///< largest region simulated in a frame
  std::vector<double> step_ms;      ///< per stepped frame: the integrator step alone
  std::vector<double> sim_cpu_ms;   ///< per frame: sim_ms in the sim thread's CPU time (unaffected by other load)
  std::vector<double> step_cpu_ms;  ///< per stepped frame: step_ms in CPU time
  int64_t frames_stepped = 0;       ///< frames whose lattice was stepped
  int64_t frames_resting = 0;       ///< frames skipped because the lattice was at rest
  int64_t node_frames = 0, spring_frames = 0, vertex_frames = 0;  ///< sums over frames of what was simulated
  int64_t region_moves = 0;         ///< times the region followed the contact
  int64_t divergence_events = 0;    ///< finite states with a spring past kDivergedStrain (reset to rest)
  int64_t contact_models = 0;       ///< frames that published a contact model for the servo, from the factor
  int64_t contact_models_estimated = 0;  ///< frames that published one estimated (factor not done, refined lattice)
  int force_nodes = 0;              ///< lattice nodes loaded by the contact force in the last frame with contact
  int64_t solved_contact_frames = 0;  ///< frames whose push went where the solved contact put it (device.contact)
  int64_t prescribed_contact_frames = 0;  ///< frames with a push loaded by formula (no factor yet, or not asked)
  double solved_contact_radius_m = 0.0;   ///< the last solved contact's radius
  int64_t substeps_total = 0;       ///< integrator substeps over all stepped frames
  int64_t implicit_splits = 0;      ///< implicit Euler substeps that failed whole and were split (StepReport)
  int64_t steps_out_of_time = 0;    ///< realtime: frames whose step ended at the frame's deadline (StepReport::out_of_time)
  int64_t projected_steps = 0;      ///< implicit Euler substeps no split could take, taken by projected Newton (StepReport)
  int64_t solver_fallbacks = 0;     ///< substeps whose solver failed (in every split and projected too): stepped explicitly
  // cut mode
  int64_t frames_cutting = 0;       ///< frames that applied blade sweeps
  int64_t springs_cut = 0;          ///< springs removed by the blade
  int64_t springs_deferred_max = 0; ///< most crossed springs left in the lattice for later frames at once
  int64_t frames_deferring = 0;     ///< frames that ended with crossed springs left for later frames
  int64_t triangles_added = 0;      ///< growth of the triangle count by mesh splits
  int64_t vertices_added = 0;       ///< growth of the vertex count by mesh splits
  int64_t cut_work_max = 0;         ///< most cut work (CutReport::work()) one frame did
  int64_t free_nodes = 0;           ///< nodes in pieces cut free of every fixed node (after the last cut)
  std::vector<double> cutting_ms;   ///< sim_ms of frames that cut
  std::vector<double> after_cut_ms; ///< sim_ms of frames after the first cut that did not cut
  std::vector<double> cut_vertices_deformed;  ///< per frame from the first cut on: mesh vertices deform() recomputed
  std::vector<double> cut_normals;  ///< per frame from the first cut on: vertex normals recomputed
  std::vector<FrameProfile> profile;  ///< per frame: where its sim time went
};

}  // namespace palpate
