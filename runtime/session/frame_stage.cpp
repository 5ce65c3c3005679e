#include "runtime/session/frame_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/clock.h"
#include "core/state_hash.h"
#include "haptics/servo/cpu_steal.h"
#include "sim/solvers/rest.h"
#include "runtime/session/region_policy_factory.h"
#include "runtime/session/surface_queries.h"

namespace palpate {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

FrameStage::FrameStage(const Scene& scene, const Model& model, SpscQueue<HapticSample>* samples,
                       TripleBuffer<LocalModel>* local_model, Renderer* renderer, PngWriter* writer, HapticLog* log)
    : scene_(scene),
      model_(model),
      rest_{&model.rest, &model.grid, &model.bindings},
      samples_(samples),
      local_model_(local_model),
      log_(log),
      outputs_(scene, model, renderer, writer, &stats_),
      lattice_contact_(scene, model, rest_, &stats_),
      through_(scene, model, &stats_),
      feed_(scene.trajectory.front().pos_m),
      stepper_(scene, &stats_),
      vertices_m_(model.rest.vertices_m) {
  stats_.sim_ms.reserve(static_cast<std::size_t>(scene.rates.frames(scene.duration_s)) + 8);
  stats_.render_ms.reserve(stats_.sim_ms.capacity());
  stats_.render_cpu_ms.reserve(stats_.sim_ms.capacity());
  stats_.profile.reserve(stats_.sim_ms.capacity());
  region_ = make_region_policy(scene, model, &stats_);
  if (region_->lattice()) region_changed();
  // a lattice built up front gets its solver's factorisation too, before the first frame's deadline (the same
  // one the first step would make)
  if (region_->prepared_ahead() && region_->lattice())
    stepper_.prepare(region_->mutable_lattice());
  // a mesh finer than the image is drawn clustered to about a pixel's edge (render.lod_min_edge_px); not in cut
  // mode, whose blade changes the triangles on every frame it cuts
  if (renderer && scene.mode != InteractionMode::kCut)
    lod_ = screen_lod(model.rest.vertices_m, region_->triangles(),
                      [r = renderer](const Vec3& p) { return r->project(p); }, scene.render.lod_min_edge_px);
}

void FrameStage::use_budget(BudgetClock* clock) {
  if (stepper_.use_budget(clock)) region_->limit_springs_cut_per_frame(kBudgetSpringsPerFrame);
}

void FrameStage::drain(int64_t frame, int64_t drain_to_tick) {
  through_.begin_frame();
  HapticSample s;
  for (const HapticSample* next; (next = samples_->front()) != nullptr && next->tick <= drain_to_tick;) {
    if (!samples_->try_pop(&s)) break;
    s.drain_frame = frame;
    if (log_) log_->append(s);
    if (LiveFeed* live = outputs_.live()) live->add_sample(s);
    ++stats_.samples;
    feed_.take(s);
    region_->add_sample(s);
    through_.tick(s);
  }
}

void FrameStage::drain_remaining() { drain(-1, INT64_MAX); }

void FrameStage::region_changed(bool wait) {
  stepper_.wake();
  lattice_contact_.region_changed(wait);
  f_ext_N_.assign(region_->lattice()->num_nodes(), Vec3::Zero());
}

void FrameStage::place_region() {
  // a sphere's centre is outside the surface: the region is built around the surface point under it
  const Vec3 at = scene_.device.sphere_tool
                      ? surface_point(vertices_m_, model_.rest.triangles[static_cast<std::size_t>(feed_.contact().contact_tri)],
                                      feed_.contact().contact_bary)
                      : feed_.contact().proxy_pos_m;
  if (region_->place(at, {&vertices_m_, &normals_})) region_changed(/*wait=*/true);
}

void FrameStage::follow_contact() {
  if (!feed_.in_contact() || feed_.contact().contact_tri < 0) return;
  // the material point under the contact, at rest: its cell is where the contact force goes
  // (a refined lattice's fine zone follows the middle of a sphere's patch, not the nearest point wandering over it)
  const Vec3 p = scene_.lattice.refine.level > 0
                     ? contact_patch_centre(rest_, tool_contact(scene_, feed_.contact()))
                     : surface_point(model_.rest.vertices_m,
                                     model_.rest.triangles[static_cast<std::size_t>(feed_.contact().contact_tri)], feed_.contact().contact_bary);
  if (region_->follow(p, {&vertices_m_, &normals_})) region_changed(/*wait=*/true);
}

FrameView FrameStage::current_view() const {
  FrameView view{};
  view.vertices_m = &vertices_m_;
  view.triangles = lod_ ? &lod_->triangles : &triangles();
  view.normals = &normals_;
  view.tool_pos_m = feed_.latest().tool_pos_m;
  view.tool_radius_m = scene_.device.tool_radius_m;
  // a sphere tool is drawn where it rests on the surface (its centre, the proxy); the spring goes to the device
  view.tool_at_proxy = scene_.device.sphere_tool;
  view.in_contact = feed_.latest().contact != ContactState::kFree;
  view.show_proxy = view.in_contact && feed_.latest().contact != ContactState::kCut;
  view.proxy_pos_m = feed_.latest().proxy_pos_m;
  // a free tool's drop line: straight down (-z) to the first surface it would land on (the rest surface)
  if (!view.in_contact && feed_.latest().tool_pos_m.allFinite()) {
    if (const auto hit = first_ray_hit(model_, feed_.latest().tool_pos_m, -Vec3::UnitZ(), 1.0, /*front_only=*/true)) {
      view.show_drop = true;
      view.drop_to_m = hit->point_m;
      view.drop_normal = hit->normal;
    }
  }
  // what may move (the rest comes from the renderer's cached layer), the blade
  region_->fill_view(feed_.latest(), &view);
  outputs_.style().apply(feed_.latest(), &view);
  return view;
}

void FrameStage::warm_up() {
  // the budget's first frame chooses from a measured step: one step of a copy of the lattice at the scene's
  // setting, on the budget's clock. The copy has the lattice's revision, so the solver uses the factor it holds
  // and refactors nothing; the lattice itself is not touched (the run is the one it would have been). A region
  // that steps no part of its lattice yet (cut mode before a piece comes free) is not measured.
  if (const Lattice* lat = region_->stepped_lattice()) stepper_.seed_budget(*lat);
  if (outputs_.renderer()) outputs_.warm(current_view());
}

void FrameStage::render(int64_t index, bool block) {
  if (uint8_t* buf = outputs_.acquire(block)) outputs_.draw(index, block, buf, current_view(), feed_.latest().force_N.norm());
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
  stepper_.begin_frame(monotonic_ns());
  lap_wall_ = t0;
  lap_cpu_ms_ = c0;
  t_s_ = t_s;
  feed_.begin_frame();
  frame_index_ = index;
  drain(index, drain_to_tick);
  feed_.end_drain();
  lap(FramePart::kDrain);
  const int64_t cut_before = stats_.springs_cut;
  if (region_->begin_frame({&vertices_m_, &normals_})) stepper_.wake();
  if (!region_->lattice() && feed_.in_contact()) place_region();
  profile_.springs_cut = static_cast<int>(stats_.springs_cut - cut_before);
  lap(FramePart::kCut);
  lattice_contact_.begin_frame(feed_.frame());
  bool moved = false;
  if (region_->lattice()) {
    follow_contact();
    if (const int nodes = lattice_contact_.load(*region_->lattice(), vertices_m_, near_tris_, feed_.frame(), &f_ext_N_);
        nodes > 0)
      stats_.force_nodes = nodes;
    lap(FramePart::kLoad);
    Lattice* stepped = region_->stepped_lattice();
    moved = stepper_.step(stepped, stepped == region_->mutable_lattice(), f_ext_N_, region_->bound_vertices(), &profile_,
                          [this](FramePart part) { lap(part); });
    if (moved) region_->after_step();
  }
  if (moved) {
    const Lattice& lat = *region_->lattice();
    lattice_moved_m_ = 0.0;
    for (std::size_t i = 0; i < lat.num_nodes(); ++i)
      lattice_moved_m_ = std::max(lattice_moved_m_, (lat.x_m[i] - lat.rest_m[i]).norm());
    stats_.max_displacement_m = std::max(stats_.max_displacement_m, lattice_moved_m_);
    through_.set_moved(lattice_moved_m_);
    region_->deform(&vertices_m_);
  }
  through_.frame(feed_.latest(), region_->lattice() ? &*region_->lattice() : nullptr, t_s_);
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
  stepper_.end_frame();
  region_->end_frame(stats_.sim_ms.back());
  ++stats_.frames;
  const std::size_t rendered = stats_.render_ms.size();
  render(index, block_on_writer);
  if (LiveFeed* live = outputs_.live())
    live->end_frame(index, t_s, stats_.sim_ms.back() + (stats_.render_ms.size() > rendered ? stats_.render_ms.back() : 0.0),
                    stats_.frames, outputs_.frames_written(), stats_.frames_dropped);
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
