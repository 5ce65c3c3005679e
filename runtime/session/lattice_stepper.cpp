#include "runtime/session/lattice_stepper.h"

#include <algorithm>
#include <chrono>

#include "sim/solvers/rest.h"

namespace palpate {

LatticeStepper::LatticeStepper(const Scene& scene, FrameStats* stats)
    : scene_(scene), stats_(stats), step_opts_(step_options(scene.lattice)) {}

bool LatticeStepper::use_budget(BudgetClock* clock) {
  if (scene_.lattice.budget_ms <= 0.0) return false;
  auto ladder = budget_ladder(step_options(scene_.lattice));
  if (ladder.empty()) return false;
  budget_.emplace(scene_.lattice.budget_ms, std::move(ladder), clock, kFramePlanFraction);
  return true;
}

void LatticeStepper::prepare(Lattice* lat) { prepare_step(*lat, step_opts_, scene_.rates.frame_period_s(), &ws_); }

void LatticeStepper::seed_budget(const Lattice& lat) {
  if (!budget_ || seeded_) return;
  seeded_ = true;
  Lattice copy = lat;
  const std::vector<Vec3> none;
  const StepOptions& opts = budget_->ladder().front().opts;
  prepare_step(copy, opts, scene_.rates.frame_period_s(), &ws_);
  const double t0 = budget_->clock()->now_ms();
  step_lattice(&copy, opts, scene_.rates.frame_period_s(), none, &ws_);
  budget_->seed_step(0, budget_->clock()->now_ms() - t0);
}

void LatticeStepper::begin_frame(int64_t start_ns) {
  frame_start_ns_ = start_ns;
  frame_opts_ = budget_ ? &budget_->begin_frame() : nullptr;
}

void LatticeStepper::end_frame() {
  if (budget_) budget_->end_frame();
}

bool LatticeStepper::step(Lattice* stepped, bool whole, const std::vector<Vec3>& whole_f_ext, std::size_t bound_vertices,
                          FrameProfile* profile, const std::function<void(FramePart)>& lap) {
  const bool pushed = max_force_N(whole_f_ext) >= scene_.lattice.rest_force_N;
  if (!stepped || (resting_ && !pushed)) {
    ++stats_->frames_resting;
    return false;
  }
  Lattice& lat = *stepped;
  // a part of the lattice (the pieces a cut frees) takes no contact force
  if (!whole) part_f_ext_N_.assign(lat.num_nodes(), Vec3::Zero());
  const std::vector<Vec3>& f_ext = whole ? whole_f_ext : part_f_ext_N_;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_clock_.now_ms();
  // the solver's matrix first (what the step would do first anyway; the rungs differ only in iterations), so the
  // budget knows what the frame has spent before choosing the iterations, and the profile tells the two apart
  prepare_step(lat, frame_opts_ ? *frame_opts_ : step_opts_, scene_.rates.frame_period_s(), &ws_);
  lap(FramePart::kFactor);
  StepOptions opts = budget_ ? budget_->step_begin() : step_opts_;
  if (deadlines_) opts.deadline_ns = frame_start_ns_ + static_cast<int64_t>(1e9 * scene_.rates.frame_period_s());
  const StepReport rep = step_lattice(&lat, opts, scene_.rates.frame_period_s(), f_ext, &ws_);
  FrameStats& st = *stats_;
  st.steps_out_of_time += rep.out_of_time ? 1 : 0;
  if (budget_) budget_->step_end();
  st.step_cpu_ms.push_back(cpu_clock_.now_ms() - c0);
  st.step_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  lap(FramePart::kStep);
  profile->iterations = rep.iterations;
  profile->cg_iterations = rep.cg_iterations;
  ++st.frames_stepped;
  st.node_frames += static_cast<int64_t>(lat.num_nodes());
  st.spring_frames += static_cast<int64_t>(lat.springs.size());
  st.vertex_frames += static_cast<int64_t>(bound_vertices);
  st.max_substeps = std::max(st.max_substeps, rep.substeps);
  st.substeps_total += rep.substeps;
  st.implicit_splits += rep.implicit_splits;
  st.projected_steps += rep.projected_steps;
  st.solver_fallbacks += rep.solver_ok ? 0 : 1;
  if (!rep.diverged) st.max_strain = std::max(st.max_strain, rep.max_strain);
  if (rep.diverged) {
    // a diverged state is counted and replaced by rest, so the run goes on
    ++(rep.finite ? st.divergence_events : st.nan_events);
    lat.reset_to_rest();
  }
  resting_ = !pushed && lattice_at_rest(lat, f_ext, scene_.lattice.rest_kinetic_J, scene_.lattice.rest_force_N,
                                        &rest_scratch_);
  return true;
}

}  // namespace palpate
