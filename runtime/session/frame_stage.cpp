#include "runtime/session/frame_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/clock.h"
#include "core/state_hash.h"
#include "haptics/cpu_steal.h"
#include "sim/compliance_estimate.h"
#include "sim/deformer.h"
#include "sim/lattice_estimate.h"
#include "sim/rest.h"
#include "runtime/session/region_policy_factory.h"
#include "runtime/session/surface_queries.h"

namespace palpate {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The contact compliance's numeric factorisation per frame, in 3x3 block updates: about 3 ms of a frame here (55 ns an
// update at load 9, measured on phantom_press's 480-node region: 486,531 updates). A region of more than 256 free
// nodes is factored in stages over frames (assembly, ordering, analysis, then these slices); the servo keeps the
// surface's own force model until it is done. Smaller regions (the bunny scenes, cube_press, tissue_pull) factor
// whole in one frame as before.
constexpr int64_t kComplianceWorkPerFrame = 50000;

// a free tool or a held proxy counts as through the surface deeper than this beyond what the material has moved
constexpr double kThroughTolerance_m = 5e-4;

}  // namespace

FrameStage::FrameStage(const Scene& scene, const Model& model, SpscQueue<HapticSample>* samples,
                       TripleBuffer<LocalModel>* local_model, Renderer* renderer, PngWriter* writer, HapticLog* log)
    : scene_(scene),
      model_(model),
      rest_{&model.rest, &model.grid, &model.bindings},
      samples_(samples),
      local_model_(local_model),
      renderer_(renderer),
      writer_(writer),
      log_(log),
      step_opts_(step_options(scene.lattice)),
      vertices_m_(model.rest.vertices_m),
      style_(scene, model) {
  latest_.tool_pos_m = scene.trajectory.front().pos_m;
  latest_.proxy_pos_m = latest_.tool_pos_m;
  stats_.sim_ms.reserve(static_cast<std::size_t>(scene.rates.frames(scene.duration_s)) + 8);
  stats_.render_ms.reserve(stats_.sim_ms.capacity());
  stats_.render_cpu_ms.reserve(stats_.sim_ms.capacity());
  stats_.profile.reserve(stats_.sim_ms.capacity());
  // a lockstep run has no deadline: a solved contact gets its factor in the first frame it is asked for, not after
  // tens of frames of slices loaded by formula (a realtime run keeps the slices and loads by formula until done)
  compliance_.set_work_per_call(scene.device.solved_contact && scene.run_mode == RunMode::kLockstep ? 0 : kComplianceWorkPerFrame);
  if (scene.mode != InteractionMode::kCut) {
    const LatticeEstimate most = estimate_lattice(model.grid, scene.lattice, false);
    compliance_.reserve(most.nodes, most.springs,
                        scene.lattice.material.enabled && scene.lattice.material.model != MaterialModel::kSprings);
  }
  region_ = make_region_policy(scene, model, &stats_);
  if (region_->lattice()) region_changed();
  // a lattice built up front gets its solver's factorisation too, before the first frame's deadline (the same
  // one the first step would make)
  if (region_->prepared_ahead() && region_->lattice())
    prepare_step(*region_->mutable_lattice(), step_opts_, scene.rates.frame_period_s(), &ws_);
  // a mesh finer than the image is drawn clustered to about a pixel's edge (render.lod_min_edge_px); not in cut
  // mode, whose blade changes the triangles on every frame it cuts
  if (renderer_ && scene.mode != InteractionMode::kCut)
    lod_ = screen_lod(model.rest.vertices_m, region_->triangles(),
                      [r = renderer_](const Vec3& p) { return r->project(p); }, scene.render.lod_min_edge_px);
}

void FrameStage::use_budget(BudgetClock* clock) {
  if (scene_.lattice.budget_ms <= 0.0) return;
  auto ladder = budget_ladder(step_options(scene_.lattice));
  if (ladder.empty()) return;
  budget_.emplace(scene_.lattice.budget_ms, std::move(ladder), clock, kFramePlanFraction);
  region_->limit_springs_cut_per_frame(kBudgetSpringsPerFrame);
}

void FrameStage::drain(int64_t frame, int64_t drain_to_tick) {
  through_still_m_ = 0.0;  // the reach may have changed with the last step: every frame asks afresh
  HapticSample s;
  for (const HapticSample* next; (next = samples_->front()) != nullptr && next->tick <= drain_to_tick;) {
    if (!samples_->try_pop(&s)) break;
    s.drain_frame = frame;
    if (log_) log_->append(s);
    if (live_) live_->add_sample(s);
    ++stats_.samples;
    ++frame_samples_;
    force_sum_N_ += s.force_N;
    drawn_peak_N_ = std::max(drawn_peak_N_, s.force_N.norm());
    if (s.contact != ContactState::kFree && s.contact_tri >= 0) {
      contact_ = s;
      contact_this_frame_ = true;
    }
    region_->add_sample(s);
    check_through(s);
    latest_ = s;
  }
}

void FrameStage::check_through(const HapticSample& s) {
  if (scene_.mode != InteractionMode::kTouch) return;
  const bool free = s.contact == ContactState::kFree;
  const Vec3& p = free ? s.tool_pos_m : s.god_pos_m;
  // a point on the deformed surface lies at most the material's move under the rest one (a sphere's centre a radius
  // above it), and a blended patch between two frames' surfaces
  const double reach_m = lattice_moved_m_ + scene_.device.tool_radius_m + kThroughTolerance_m;
  // the last answer holds while the point stays this near where it was asked (a proxy sliding on the surface is
  // asked about once or twice a frame, not every tick)
  if (through_still_m_ > 0.0 && (p - through_at_m_).norm() < through_still_m_) return;
  through_at_m_ = p;
  if (depth_inside(model_, p, reach_m, &through_still_m_) == 0.0) return;
  ++(free ? stats_.tool_inside_ticks : stats_.proxy_inside_ticks);
  if (stats_.through_first_t_s < 0.0) stats_.through_first_t_s = s.t_s;
}

void FrameStage::keep_contact_through_silence() {
  if (frame_samples_ > 0) {
    last_mean_force_N_ = force_sum_N_ / static_cast<double>(frame_samples_);
    return;
  }
  // the servo sent nothing since the last frame (it stalled): the hand is where it last was, holding what it held
  if (latest_.contact == ContactState::kFree || latest_.contact_tri < 0) return;
  contact_this_frame_ = true;
  force_sum_N_ = last_mean_force_N_;
  frame_samples_ = 1;
}

void FrameStage::drain_remaining() { drain(-1, INT64_MAX); }

void FrameStage::region_changed() {
  resting_ = false;
  solved_.reset();
  f_ext_N_.assign(region_->lattice()->num_nodes(), Vec3::Zero());
}

void FrameStage::place_region() {
  // a sphere's centre is outside the surface: the region is built around the surface point under it
  const Vec3 at = scene_.device.sphere_tool
                      ? surface_point(vertices_m_, model_.rest.triangles[static_cast<std::size_t>(contact_.contact_tri)],
                                      contact_.contact_bary)
                      : contact_.proxy_pos_m;
  if (region_->place(at, {&vertices_m_, &normals_})) {
    region_changed();
    compliance_next_frame_ = true;
  }
}

void FrameStage::follow_contact() {
  if (!contact_this_frame_ || contact_.contact_tri < 0) return;
  // the material point under the contact, at rest: its cell is where the contact force goes
  // (a refined lattice's fine zone follows the middle of a sphere's patch, not the nearest point wandering over it)
  const Vec3 p = scene_.lattice.refine.level > 0
                     ? contact_patch_centre(rest_, tool_contact(contact_))
                     : surface_point(model_.rest.vertices_m,
                                     model_.rest.triangles[static_cast<std::size_t>(contact_.contact_tri)], contact_.contact_bary);
  if (region_->follow(p, {&vertices_m_, &normals_})) {
    region_changed();
    compliance_next_frame_ = true;
  }
}

bool FrameStage::step_lattice_frame() {
  const bool pushed = max_force_N(f_ext_N_) >= scene_.lattice.rest_force_N;
  Lattice* stepped = region_->stepped_lattice();
  if (!stepped || (resting_ && !pushed)) {
    ++stats_.frames_resting;
    return false;
  }
  Lattice& lat = *stepped;
  // a part of the lattice (the pieces a cut frees) takes no contact force
  if (stepped != region_->mutable_lattice()) part_f_ext_N_.assign(lat.num_nodes(), Vec3::Zero());
  const std::vector<Vec3>& f_ext = stepped != region_->mutable_lattice() ? part_f_ext_N_ : f_ext_N_;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_clock_.now_ms();
  // the solver's matrix first (what the step would do first anyway; the rungs differ only in iterations), so the
  // budget knows what the frame has spent before choosing the iterations, and the profile tells the two apart
  prepare_step(lat, frame_opts_ ? *frame_opts_ : step_opts_, scene_.rates.frame_period_s(), &ws_);
  lap(FramePart::kFactor);
  StepOptions opts = budget_ ? budget_->step_begin() : step_opts_;
  if (deadlines_) opts.deadline_ns = frame_start_ns_ + static_cast<int64_t>(1e9 * scene_.rates.frame_period_s());
  const StepReport rep = step_lattice(&lat, opts, scene_.rates.frame_period_s(), f_ext, &ws_);
  stats_.steps_out_of_time += rep.out_of_time ? 1 : 0;
  if (budget_) budget_->step_end();
  stats_.step_cpu_ms.push_back(cpu_clock_.now_ms() - c0);
  stats_.step_ms.push_back(ms_since(t0));
  lap(FramePart::kStep);
  profile_.iterations = rep.iterations;
  profile_.cg_iterations = rep.cg_iterations;
  ++stats_.frames_stepped;
  stats_.node_frames += static_cast<int64_t>(lat.num_nodes());
  stats_.spring_frames += static_cast<int64_t>(lat.springs.size());
  stats_.vertex_frames += static_cast<int64_t>(region_->bound_vertices());
  stats_.max_substeps = std::max(stats_.max_substeps, rep.substeps);
  stats_.substeps_total += rep.substeps;
  stats_.implicit_splits += rep.implicit_splits;
  stats_.projected_steps += rep.projected_steps;
  stats_.solver_fallbacks += rep.solver_ok ? 0 : 1;
  if (!rep.diverged) stats_.max_strain = std::max(stats_.max_strain, rep.max_strain);
  if (rep.diverged) {
    // a diverged state is counted and replaced by rest, so the run goes on
    ++(rep.finite ? stats_.divergence_events : stats_.nan_events);
    lat.reset_to_rest();
  }
  resting_ = !pushed && lattice_at_rest(lat, f_ext, scene_.lattice.rest_kinetic_J, scene_.lattice.rest_force_N,
                                        &rest_scratch_);
  return true;
}

ToolContact FrameStage::tool_contact(const HapticSample& s) const {
  ToolContact c;
  c.tri = s.contact_tri;
  c.bary = s.contact_bary;
  c.centre_m = s.proxy_pos_m;
  c.sphere = scene_.device.sphere_tool;
  c.radius_m = scene_.device.tool_radius_m;
  return c;
}

int FrameStage::apply_contact_force(std::vector<Vec3>* f_ext) {
  std::fill(f_ext->begin(), f_ext->end(), Vec3::Zero());
  solved_this_frame_ = false;
  if (!contact_this_frame_ || frame_samples_ == 0) {
    solved_.reset();
    return 0;
  }
  // the frame's mean device force, reacted on the material point P_s: -F spread over the cell nodes of the
  // contact triangle's vertices by barycentric and trilinear weights (a sphere tool: over its contact patch), or
  // (device.contact "solved") where the surface, deformed by it, meets the tool's tip
  const ToolContact c = tool_contact(contact_);
  const Vec3 f_obj = object_force(rest_, c, -force_sum_N_ / static_cast<double>(frame_samples_));
  if (scene_.device.solved_contact) {
    // a sphere tool's centre is the proxy; a point tool's tip is a sphere of its radius resting on the proxy
    const double radius = scene_.device.tool_radius_m;
    const Vec3 push = f_obj.norm() > 0.0 ? Vec3(f_obj.normalized()) : Vec3::Zero();
    const Vec3 centre = c.sphere ? c.centre_m : Vec3(contact_.proxy_pos_m - radius * push);
    solved_this_frame_ = solved_.weights(*region_->lattice(), rest_, vertices_m_, near_tris_, centre, radius, f_obj,
                                         &compliance_, &solved_w_);
  }
  if (solved_this_frame_) {
    ++stats_.solved_contact_frames;
    stats_.solved_contact_radius_m = solved_.report().contact_radius_m;
  } else {
    ++stats_.prescribed_contact_frames;
  }
  const PointWeights w = solved_this_frame_ ? solved_w_ : contact_load_weights(*region_->lattice(), rest_, c);
  for (int i = 0; i < w.count; ++i) (*f_ext)[w.node[i]] += w.weight[i] * f_obj;
  int loaded = 0;
  for (const Vec3& f : *f_ext) loaded += f.squaredNorm() > 0.0 ? 1 : 0;
  return loaded;
}

std::optional<Mat3> FrameStage::needed_estimate(const Lattice& lat, const PointWeights& w) {
  // the estimate is a point load's (a node's stiffness): a sphere's patch is many times stiffer. Given the node's
  // compliance the servo let the soft cube_press's sphere (level 6) leave the surface as the hand lifted off while the
  // frame's dent was still deep, and the next frames' surface met it again a millimetre up: steps of 0.25 N
  if (scene_.device.sphere_tool) return std::nullopt;
  const Mat3 c = estimate_compliance(lat, w, &estimate_scratch_);
  // only where the sampled force alone would overshoot (sim/compliance_estimate.h: kEstimateNeededGain); on a stiffer
  // surface it settles as before, and an estimate several times too compliant would make the servo lag it
  if (!(scene_.device.coupling_N_per_m * c.trace() / 3.0 >= kEstimateNeededGain)) return std::nullopt;
  return c;
}

void FrameStage::fill_contact_model(LocalModel* m) {
  m->has_contact_model = false;
  // a region placed or moved this frame has already built its lattice and the solver's factor: its compliance
  // factor waits a frame, and the servo keeps the surface's own force model until then
  if (compliance_next_frame_) {
    compliance_next_frame_ = false;
    return;
  }
  if (!region_->lattice()) return;
  const Lattice& lat = *region_->lattice();
  // a free tool gets the model at its last contact too, on a surface far softer than the coupling: a touch that
  // begins within the next frame is then sampled against the surface's response, not against the surface as the
  // frame left it (that force, loaded as it is, would drive the surface many times the tool's depth past it, and the
  // touch would end again: a release and re-touch cycle). On a stiffer surface the sampled force settles as before.
  const bool free = latest_.contact == ContactState::kFree || latest_.contact_tri < 0;
  const HapticSample& at = free ? contact_ : latest_;
  if (at.contact_tri < 0) return;
  const PointWeights w = solved_this_frame_ && !free ? solved_w_ : contact_load_weights(lat, rest_, tool_contact(at));
  // a free tool's model is the estimate's case only (and computed once)
  std::optional<Mat3> estimate;
  if (free && !(estimate = needed_estimate(lat, w))) return;
  const Vec3 p = surface_point(vertices_m_, model_.rest.triangles[static_cast<std::size_t>(at.contact_tri)],
                               at.contact_bary);
  ContactResponse r;
  if (contact_response(lat, w, p, frame_force_obj_N_, &compliance_, &r)) {
    ++stats_.contact_models;
  } else {
    // a refined lattice has no condensed compliance; a solved contact still needs its stiffness factored
    if (scene_.device.solved_contact && !lat.hanging.empty()) {
      Mat3 c;
      compliance_.compute(lat, w, false, &c);
    }
    // while the factor is made in slices, or on a refined lattice, the servo takes the estimate where it needs one; a
    // singular lattice (a piece with nothing holding it) gets no model
    if (!compliance_.factoring() && lat.hanging.empty()) return;
    if (!estimate) estimate = needed_estimate(lat, w);
    if (!estimate || !contact_response_with(lat, w, p, frame_force_obj_N_, *estimate, &r)) return;
    ++stats_.contact_models_estimated;
  }
  m->has_contact_model = true;
  m->contact_p0_m = r.p0_m;
  m->contact_centre_m = at.god_pos_m;
  m->contact_v0_m_per_s = r.v0_m_per_s;
  m->contact_f0_N = r.f0_N;
  m->compliance_m_per_N = r.compliance_m_per_N;
  m->model_radius_m = r.radius_m;
}

void FrameStage::check_tool_inside() {
  if (scene_.mode != InteractionMode::kTouch || latest_.contact != ContactState::kFree) return;
  if (proven_depth_inside(model_, latest_.tool_pos_m, 0.0) == 0.0) return;  // a few cells decide the usual case
  double moved = 0.0;
  if (const auto& lat = region_->lattice())
    for (std::size_t i = 0; i < lat->num_nodes(); ++i) moved = std::max(moved, (lat->x_m[i] - lat->rest_m[i]).norm());
  const double depth = proven_depth_inside(model_, latest_.tool_pos_m, moved + scene_.device.tool_radius_m);
  if (depth == 0.0) return;
  if (stats_.tool_inside_frames++ == 0) {
    stats_.tool_inside_first_t_s = t_s_;
    stats_.tool_inside_depth_m = depth;
  }
}

FrameView FrameStage::current_view() const {
  FrameView view{};
  view.vertices_m = &vertices_m_;
  view.triangles = lod_ ? &lod_->triangles : &triangles();
  view.normals = &normals_;
  view.tool_pos_m = latest_.tool_pos_m;
  view.tool_radius_m = scene_.device.tool_radius_m;
  // a sphere tool is drawn where it rests on the surface (its centre, the proxy); the spring goes to the device
  view.tool_at_proxy = scene_.device.sphere_tool;
  view.in_contact = latest_.contact != ContactState::kFree;
  view.show_proxy = view.in_contact && latest_.contact != ContactState::kCut;
  view.proxy_pos_m = latest_.proxy_pos_m;
  // a free tool's drop line: straight down (-z) to the first surface it would land on (the rest surface)
  if (!view.in_contact && latest_.tool_pos_m.allFinite()) {
    if (const auto hit = first_ray_hit(model_, latest_.tool_pos_m, -Vec3::UnitZ(), 1.0, /*front_only=*/true)) {
      view.show_drop = true;
      view.drop_to_m = hit->point_m;
      view.drop_normal = hit->normal;
    }
  }
  // what may move (the rest comes from the renderer's cached layer), the blade
  region_->fill_view(latest_, &view);
  style_.apply(latest_, &view);
  return view;
}

void FrameStage::warm_up() {
  // the budget's first frame chooses from a measured step: one step of a copy of the lattice at the scene's
  // setting, on the budget's clock. The copy has the lattice's revision, so the solver uses the factor it holds
  // and refactors nothing; the lattice itself is not touched (the run is the one it would have been). A region
  // that steps no part of its lattice yet (cut mode before a piece comes free) is not measured.
  if (budget_ && region_->stepped_lattice() && !dry_stepped_) {
    dry_stepped_ = true;
    Lattice copy = *region_->stepped_lattice();
    const std::vector<Vec3> none;
    const StepOptions& opts = budget_->ladder().front().opts;
    prepare_step(copy, opts, scene_.rates.frame_period_s(), &ws_);
    const double t0 = budget_->clock()->now_ms();
    step_lattice(&copy, opts, scene_.rates.frame_period_s(), none, &ws_);
    budget_->seed_step(0, budget_->clock()->now_ms() - t0);
  }
  if (!renderer_) return;
  warm_rgba_.resize(static_cast<std::size_t>(renderer_->width()) * static_cast<std::size_t>(renderer_->height()) * 4);
  renderer_->draw(current_view(), warm_rgba_.data());
}

void FrameStage::render(int64_t index, bool block) {
  if (!renderer_ || !writer_) return;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_clock_.now_ms();
  const int64_t builds = renderer_->layer_builds();
  uint8_t* buf = writer_->acquire(block);
  if (!buf) {
    ++stats_.frames_dropped;
    return;
  }
  // the trace takes the largest force the hand got since the last frame drawn (the latest when no tick came)
  style_.note_force(drawn_peak_N_ >= 0.0 ? drawn_peak_N_ : latest_.force_N.norm());
  drawn_peak_N_ = -1.0;
  const FrameView view = current_view();
  renderer_->draw(view, buf);
  style_.observe(view);
  stats_.frames_layered += renderer_->last_draw_layered() ? 1 : 0;
  // the video gets its own copy: its frame index is the scene's, so a skipped frame holds the last one shown
  if (video_) video_->submit(index, buf, block);
  if (live_) live_->offer_frame(index, buf);
  // files are numbered in the order written, so a realtime run's skipped frames leave no gap in the sequence;
  // written_frames says which scene frame each file shows
  writer_->submit(static_cast<int>(stats_.frames_rendered), buf);
  stats_.written_frames.push_back(index);
  ++stats_.frames_rendered;
  stats_.render_ms.push_back(ms_since(t0));
  stats_.render_cpu_ms.push_back(cpu_clock_.now_ms() - c0);
  if (renderer_->layer_builds() != builds) {
    stats_.layer_build_ms.push_back(stats_.render_ms.back());
    stats_.layer_build_cpu_ms.push_back(stats_.render_cpu_ms.back());
    stats_.layer_build_px.push_back(static_cast<double>(renderer_->last_layer_px()));
  }
}

void FrameStage::lap(FramePart part) {
  const auto now = std::chrono::steady_clock::now();
  const double cpu = cpu_clock_.now_ms();
  const auto i = static_cast<std::size_t>(part);
  profile_.wall_ms[i] += std::chrono::duration<double, std::milli>(now - lap_wall_).count();
  profile_.cpu_ms[i] += cpu - lap_cpu_ms_;
  lap_wall_ = now;
  lap_cpu_ms_ = cpu;
}

void FrameStage::frame(int64_t index, double t_s, bool block_on_writer, int64_t drain_to_tick) {
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_clock_.now_ms();
  const ThreadSwitches sw0 = this_thread_switches();
  profile_ = FrameProfile{};
  profile_.frame = index;
  frame_start_ns_ = monotonic_ns();
  lap_wall_ = t0;
  lap_cpu_ms_ = c0;
  frame_opts_ = budget_ ? &budget_->begin_frame() : nullptr;
  t_s_ = t_s;
  contact_this_frame_ = false;
  solved_this_frame_ = false;
  force_sum_N_.setZero();
  frame_samples_ = 0;
  frame_index_ = index;
  drain(index, drain_to_tick);
  keep_contact_through_silence();
  lap(FramePart::kDrain);
  const int64_t cut_before = stats_.springs_cut;
  if (region_->begin_frame({&vertices_m_, &normals_})) resting_ = false;
  if (!region_->lattice() && contact_this_frame_) place_region();
  profile_.springs_cut = static_cast<int>(stats_.springs_cut - cut_before);
  lap(FramePart::kCut);
  frame_force_obj_N_ = contact_this_frame_ && frame_samples_ > 0
                           ? object_force(rest_, tool_contact(contact_), -force_sum_N_ / static_cast<double>(frame_samples_))
                           : Vec3::Zero();
  bool moved = false;
  if (region_->lattice()) {
    follow_contact();
    if (const int nodes = apply_contact_force(&f_ext_N_); nodes > 0) stats_.force_nodes = nodes;
    lap(FramePart::kLoad);
    moved = step_lattice_frame();
    if (moved) region_->after_step();
  }
  if (moved) {
    const Lattice& lat = *region_->lattice();
    lattice_moved_m_ = 0.0;
    for (std::size_t i = 0; i < lat.num_nodes(); ++i)
      lattice_moved_m_ = std::max(lattice_moved_m_, (lat.x_m[i] - lat.rest_m[i]).norm());
    stats_.max_displacement_m = std::max(stats_.max_displacement_m, lattice_moved_m_);
    region_->deform(&vertices_m_);
  }
  check_tool_inside();
  lap(FramePart::kDeform);
  // normals for the servo's inside test and for shading: those the frame can have changed
  region_->update_normals(moved, {&vertices_m_, &normals_});
  lap(FramePart::kNormals);
  publish_patch();
  lap(FramePart::kPatch);
  stats_.sim_ms.push_back(ms_since(t0));
  stats_.sim_cpu_ms.push_back(cpu_clock_.now_ms() - c0);
  const ThreadSwitches sw1 = this_thread_switches();
  profile_.frame_wall_ms = stats_.sim_ms.back();
  profile_.frame_cpu_ms = stats_.sim_cpu_ms.back();
  if (sw0.involuntary >= 0 && sw1.involuntary >= 0) profile_.involuntary_switches = sw1.involuntary - sw0.involuntary;
  stats_.profile.push_back(profile_);
  if (budget_) budget_->end_frame();
  region_->end_frame(stats_.sim_ms.back());
  ++stats_.frames;
  const std::size_t rendered = stats_.render_ms.size();
  render(index, block_on_writer);
  if (live_)
    live_->end_frame(index, t_s, stats_.sim_ms.back() + (stats_.render_ms.size() > rendered ? stats_.render_ms.back() : 0.0),
                     stats_.frames, writer_ ? writer_->frames_written() : 0, stats_.frames_dropped);
}

std::string FrameStage::state_hash() const {
  StateHash h;
  if (const auto& lat = region_->lattice()) {
    h.add(lat->x_m);
    h.add(lat->v_m_per_s);
  }
  h.add(vertices_m_);
  return h.hex();
}

}  // namespace palpate
