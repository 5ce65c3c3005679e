#pragma once
/// A frame budget the sim keeps (opt-in `lattice.budget_ms`): a ladder of step settings from the scene's own
/// (most accurate) down to the cheapest, and a controller that picks, before each frame, the most accurate setting
/// whose predicted cost holds the planned part of the budget (plan_ms()), and takes a cheaper one for a frame whose
/// work before the step (a cut, its factor update) leaves too little of it. The prediction comes only from what was measured this run: the
/// parts of the frame the setting does not change (before the step: drain, cut, factor update; after it: deform,
/// normals, patch), and the step's cost per unit of work of the setting that ran, each a running estimate that
/// rises at once with a dearer frame and falls back gradually.
/// Costs are read from a clock the caller supplies, so the controller's decisions can be driven exactly in tests.

#include <cstdint>
#include <string>
#include <vector>

#include "sim/solvers/integrator.h"

namespace palpate {

/// Where frame costs are read from, in milliseconds. Thread: the caller's.
class BudgetClock {
 public:
  virtual ~BudgetClock() = default;
  /// Current time in ms (any origin; only differences are used).
  virtual double now_ms() = 0;
};

/// The wall clock (std::chrono::steady_clock): a realtime frame's deadline is in wall time.
class WallClock final : public BudgetClock {
 public:
  double now_ms() override;
};

/// The calling thread's CPU time (CLOCK_THREAD_CPUTIME_ID): what a frame costs whatever else the machine runs.
class ThreadCpuClock final : public BudgetClock {
 public:
  double now_ms() override;
};

/// One rung of the ladder. Plain data.
struct BudgetSetting {
  StepOptions opts;            ///< how to step at this rung
  double work_units = 1.0;     ///< relative step cost (local/global: iterations + kLocalGlobalFixedUnits)
  double error_node_rms_cell = -1.0;  ///< time-integration error of this setting against RK4 (see error_source); < 0 unknown
};

/// The fixed part of a local/global step in units of one iteration (the constant right-hand side and the state
/// update): `palpate bench sim scenes/bunny_cut.json --box 8 --integrators local_global --iterations 10 6 4 3 2 1`
/// measured 1.875 ms CPU at 10 iterations, 0.780 at 4 and 0.414 at 2 (a line through them: 0.18 ms an iteration
/// plus 0.05 ms, about a quarter of one).
inline constexpr double kLocalGlobalFixedUnits = 0.25;

/// Node error rms / cell of local_global at `iterations` (one substep a frame) against an RK4 reference on a box of
/// bunny_cut's material, as measured once by the command in kBudgetErrorSource (the table the code carries; other
/// materials and loads carry other errors). < 0 when the table has no such row.
double bunny_cut_local_global_error(int iterations);

/// Where the errors in the ladder come from (for the summary).
inline constexpr const char* kBudgetErrorSource =
    "palpate bench sim scenes/bunny_cut.json --box 8 --integrators local_global --iterations 10 6 4 3 2 1: node rms / "
    "cell against rk4 x64 substeps, 729-node box of bunny_cut's k, m, c under a 0.3 N pull, measured once (a table "
    "in the code; other materials and loads differ)";

/// The ladder for a scene's step options: the scene's setting first, then local_global at fewer iterations
/// (6, 4, 3, 2, 1 below the scene's). Empty when the integrator has nothing to trade (only local_global has).
std::vector<BudgetSetting> budget_ladder(const StepOptions& scene_opts);

/// The share of the budget a recording's frames are planned to hold (FrameStage::use_budget). A frame costs more
/// than predicted when the servo's ticks or other threads preempt it or its caches went cold: bunny_cut in
/// `--mode realtime`, planned to all of its 8 ms, had a sim p99 of 8.1-8.3 ms in three runs (7.8-11.0 in five
/// earlier), its slowest frames showing 8-10 involuntary context switches; planned to 7 ms, 7.2-8.0 ms.
inline constexpr double kFramePlanFraction = 0.875;

/// Under a budget, the springs a frame's cut takes out of the lattice at most (CutModel::set_max_springs_per_apply):
/// one downdate batch (DowndatableLLT::kBatch columns, one sweep up the factor). The others crossed wait for the
/// next frames. On bunny_cut in `--mode realtime` a stroke crosses about 60 springs every fourth frame, whose
/// downdates took 5-7 ms of one frame and set the sim p99 (8.3-9.2 ms in two of five runs); limited to 16, nine
/// runs at 16, 24 and 32 had p99 6.97-7.53 ms.
inline constexpr int kBudgetSpringsPerFrame = 16;

/// The controller. Deterministic given the clock's readings. Thread: the sim thread.
class FrameBudget {
 public:
  /// budget_ms > 0; ladder not empty (most accurate first); clock must outlive this. Settings are planned to
  /// hold plan_fraction of the budget (in (0, 1]): the room left is for frames that cost more than predicted.
  FrameBudget(double budget_ms, std::vector<BudgetSetting> ladder, BudgetClock* clock, double plan_fraction = 1.0);

  /// A step of `step_ms` at rung i measured outside the run (a dry step of a copy before the clock starts): seeds
  /// the per-unit step estimate when there is none, so the first frame chooses from a measurement instead of
  /// stepping at the scene's setting unmeasured (10 local/global iterations on bunny_cut: 10-13 ms of an 8 ms
  /// budget).
  void seed_step(int i, double step_ms);
  /// Marks the start of a frame and returns the setting planned for it (the rung current() names).
  const StepOptions& begin_frame();
  /// Marks the start of the lattice step within the frame and returns the setting to step with: the planned one,
  /// or a cheaper one when the time the frame has already spent (a cut and its factor update come before the
  /// step), the step at this run's measured cost per unit and the rest of the frame as estimated would not hold
  /// plan_ms() at the planned rung (the most accurate cheaper rung that would, else the cheapest). Only this
  /// frame steps cheaper; the plan for the next frames is made at end_frame().
  const StepOptions& step_begin();
  /// Marks the end of the lattice step (a frame that does not step marks neither).
  void step_end();
  /// Marks the end of the frame: its costs update the estimates and choose the next frame's setting.
  void end_frame();

  /// Index of the rung planned for the current (or next) frame.
  int current() const { return current_; }
  /// Index of the rung the last step_begin() chose.
  int stepped_at() const { return ran_; }
  const std::vector<BudgetSetting>& ladder() const { return ladder_; }
  /// Predicted cost in ms of the frame's remainder at rung i once `elapsed_ms` are spent before its step.
  double predicted_from_step_ms(int i, double elapsed_ms) const;
  /// Frames stepped cheaper than planned because of what they spent before the step.
  int64_t frames_stepped_cheaper() const { return cheaper_; }
  /// Frames run at each rung.
  const std::vector<int64_t>& frames_at() const { return frames_at_; }
  /// Frames whose measured cost exceeded the budget.
  int64_t frames_over() const { return frames_over_; }
  /// Rung changes.
  int64_t changes() const { return changes_; }
  /// Predicted cost in ms of a frame at rung i under the current estimates (for tests and reports).
  double predicted_ms(int i) const;
  double budget_ms() const { return budget_ms_; }
  /// What settings are planned to hold: plan_fraction of the budget.
  double plan_ms() const { return plan_ms_; }
  /// The clock costs are read from.
  BudgetClock* clock() const { return clock_; }

  /// A better rung is taken only when predicted within this fraction of plan_ms(), and only after this many
  /// frames at the current one (no flapping between two rungs).
  static constexpr double kUpFraction = 0.8;
  static constexpr int kHoldFrames = 10;
  /// Weight of a new cheaper measurement in the running estimates (a dearer one replaces them at once).
  static constexpr double kFallRate = 0.2;

 private:
  double budget_ms_;
  double plan_ms_;
  std::vector<BudgetSetting> ladder_;
  BudgetClock* clock_;
  int current_ = 0;
  int ran_ = 0;                // the rung this frame stepped at (current_ when it did not step)
  int held_ = 0;
  double t_frame_ = 0.0, t_step_ = 0.0, t_step_end_ = 0.0, step_ms_ = 0.0;
  bool stepped_ = false;
  double pre_ms_ = -1.0;       // estimate of the frame before its step (< 0: none yet)
  double tail_ms_ = -1.0;      // estimate of the frame after its step (< 0: none yet)
  double unit_ms_ = -1.0;      // estimate of the step per work unit (< 0: none yet)
  std::vector<int64_t> frames_at_;
  int64_t frames_over_ = 0, changes_ = 0, cheaper_ = 0;
};

}  // namespace palpate
