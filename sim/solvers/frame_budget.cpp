#include "sim/solvers/frame_budget.h"

#include "core/thread_cpu.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <utility>

namespace palpate {

double WallClock::now_ms() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double ThreadCpuClock::now_ms() { return thread_cpu_ms(); }

double bunny_cut_local_global_error(int iterations) {
  // measured once (README, "Frame budget"): node rms / cell against rk4 x64 substeps on an 8^3-cell box of
  // bunny_cut's k, m, c under bench sim --box's pull (a converged reference; the cut replay's own rk4 reference
  // differs from half its substeps by 3.8 cells once the ears fall, so it cannot rank these)
  struct Row {
    int iterations;
    double node_rms_cell;
  };
  static constexpr Row kTable[] = {{10, 1.15e-3}, {6, 1.18e-3}, {4, 1.25e-3},
                                       {3, 1.32e-3}, {2, 1.49e-3}, {1, 1.92e-3}};
  for (const Row& r : kTable)
    if (r.iterations == iterations) return r.node_rms_cell;
  return -1.0;
}

std::vector<BudgetSetting> budget_ladder(const StepOptions& scene_opts) {
  std::vector<BudgetSetting> ladder;
  if (scene_opts.kind != IntegratorKind::kLocalGlobal) return ladder;
  const int top = scene_opts.iterations > 0 ? scene_opts.iterations : kDefaultLocalGlobalIterations;
  auto rung = [&](int iterations) {
    BudgetSetting s;
    s.opts = scene_opts;
    s.opts.iterations = iterations;
    s.work_units = std::max(1, scene_opts.substeps) * (iterations + kLocalGlobalFixedUnits);
    s.error_node_rms_cell = scene_opts.substeps <= 1 ? bunny_cut_local_global_error(iterations) : -1.0;
    ladder.push_back(s);
  };
  rung(top);
  for (int it : {6, 4, 3, 2, 1})
    if (it < top) rung(it);
  return ladder;
}

FrameBudget::FrameBudget(double budget_ms, std::vector<BudgetSetting> ladder, BudgetClock* clock, double plan_fraction)
    : budget_ms_(budget_ms),
      plan_ms_(budget_ms * std::clamp(plan_fraction, 1e-3, 1.0)),
      ladder_(std::move(ladder)),
      clock_(clock),
      frames_at_(ladder_.size(), 0) {}

void FrameBudget::seed_step(int i, double step_ms) {
  if (unit_ms_ >= 0.0 || i < 0 || i >= static_cast<int>(ladder_.size()) || !(step_ms >= 0.0)) return;
  unit_ms_ = step_ms / ladder_[static_cast<std::size_t>(i)].work_units;
}

const StepOptions& FrameBudget::begin_frame() {
  t_frame_ = clock_->now_ms();
  stepped_ = false;
  step_ms_ = 0.0;
  ran_ = current_;
  return ladder_[static_cast<std::size_t>(current_)].opts;
}

double FrameBudget::predicted_from_step_ms(int i, double elapsed_ms) const {
  return elapsed_ms + std::max(0.0, unit_ms_) * ladder_[static_cast<std::size_t>(i)].work_units + std::max(0.0, tail_ms_);
}

const StepOptions& FrameBudget::step_begin() {
  t_step_ = clock_->now_ms();
  const double elapsed = t_step_ - t_frame_;
  ran_ = current_;
  if (predicted_from_step_ms(current_, elapsed) > plan_ms_) {
    const int n = static_cast<int>(ladder_.size());
    ran_ = n - 1;
    for (int i = current_ + 1; i < n; ++i)
      if (predicted_from_step_ms(i, elapsed) <= plan_ms_) {
        ran_ = i;
        break;
      }
    if (ran_ != current_) ++cheaper_;
  }
  return ladder_[static_cast<std::size_t>(ran_)].opts;
}

void FrameBudget::step_end() {
  t_step_end_ = clock_->now_ms();
  step_ms_ += t_step_end_ - t_step_;
  stepped_ = true;
}

double FrameBudget::predicted_ms(int i) const {
  return std::max(0.0, pre_ms_) + std::max(0.0, unit_ms_) * ladder_[static_cast<std::size_t>(i)].work_units +
         std::max(0.0, tail_ms_);
}

void FrameBudget::end_frame() {
  const double t_end = clock_->now_ms();
  const double total_ms = t_end - t_frame_;
  ++frames_at_[static_cast<std::size_t>(ran_)];
  if (total_ms > budget_ms_) ++frames_over_;
  // running estimates: a dearer frame counts at once, a cheaper one gradually
  auto track = [](double* est, double m) { *est = *est < 0.0 || m > *est ? m : *est + kFallRate * (m - *est); };
  if (stepped_) {
    track(&pre_ms_, std::max(0.0, t_step_ - t_frame_));
    track(&tail_ms_, std::max(0.0, t_end - t_step_end_));
    track(&unit_ms_, step_ms_ / ladder_[static_cast<std::size_t>(ran_)].work_units);
  } else {
    // a frame that did not step: all of it before a step that would have come, none after
    track(&pre_ms_, std::max(0.0, total_ms - std::max(0.0, tail_ms_)));
  }
  ++held_;
  const int n = static_cast<int>(ladder_.size());
  int next = current_;
  if (predicted_ms(current_) > plan_ms_) {
    // over: the most accurate cheaper rung predicted to hold the budget, else the cheapest
    next = n - 1;
    for (int i = current_ + 1; i < n; ++i)
      if (predicted_ms(i) <= plan_ms_) {
        next = i;
        break;
      }
  } else if (current_ > 0 && held_ >= kHoldFrames) {
    // room: the most accurate rung predicted well within the budget
    for (int i = 0; i < current_; ++i)
      if (predicted_ms(i) <= kUpFraction * plan_ms_) {
        next = i;
        break;
      }
  }
  if (next != current_) {
    current_ = next;
    held_ = 0;
    ++changes_;
  }
}

}  // namespace palpate
