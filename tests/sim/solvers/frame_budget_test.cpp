// The frame budget controller driven by an injected clock: frame costs are made up exactly (a fixed part plus a
// cost per unit of the step's work), so each decision can be checked against the budget arithmetic.

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "sim/solvers/frame_budget.h"

namespace palpate {
namespace {

class FakeClock final : public BudgetClock {
 public:
  double now_ms() override { return t_ms; }
  double t_ms = 1000.0;
};

StepOptions local_global(int iterations) {
  StepOptions o;
  o.kind = IntegratorKind::kLocalGlobal;
  o.iterations = iterations;
  return o;
}

// One frame whose step costs ms_per_unit per work unit of the rung it steps at, plus other_ms around it (half
// before the step, or before_ms when given: a cut and its factor update come before the step). Returns the
// iterations it stepped with.
int run_frame(FrameBudget* b, FakeClock* c, double other_ms, double ms_per_unit, double before_ms = -1.0) {
  b->begin_frame();
  c->t_ms += before_ms >= 0.0 ? before_ms : 0.5 * other_ms;
  const StepOptions& o = b->step_begin();
  const double units = b->ladder()[static_cast<std::size_t>(b->stepped_at())].work_units;
  c->t_ms += ms_per_unit * units;
  b->step_end();
  c->t_ms += 0.5 * other_ms;
  const int iterations = o.iterations;
  b->end_frame();
  return iterations;
}

TEST(FrameBudget, LadderGoesFromTheScenesIterationsDown) {
  auto iters = [](const std::vector<BudgetSetting>& l) {
    std::vector<int> v;
    for (const auto& s : l) v.push_back(s.opts.iterations);
    return v;
  };
  EXPECT_EQ(iters(budget_ladder(local_global(0))), (std::vector<int>{10, 6, 4, 3, 2, 1}));
  EXPECT_EQ(iters(budget_ladder(local_global(4))), (std::vector<int>{4, 3, 2, 1}));
  EXPECT_EQ(iters(budget_ladder(local_global(1))), (std::vector<int>{1}));
  StepOptions s;
  s.kind = IntegratorKind::kSymplecticEuler;
  EXPECT_TRUE(budget_ladder(s).empty());
  // work units: iterations plus the fixed part; cheaper down the ladder; errors from the measured table
  const auto l = budget_ladder(local_global(0));
  EXPECT_DOUBLE_EQ(l[0].work_units, 10.0 + kLocalGlobalFixedUnits);
  for (std::size_t i = 1; i < l.size(); ++i) {
    EXPECT_LT(l[i].work_units, l[i - 1].work_units);
    EXPECT_GT(l[i].error_node_rms_cell, 0.0);
    EXPECT_GE(l[i].error_node_rms_cell, l[i - 1].error_node_rms_cell);
  }
}

TEST(FrameBudget, KeepsTheScenesSettingWhileItHoldsTheBudget) {
  FakeClock clock;
  FrameBudget b(8.0, budget_ladder(local_global(0)), &clock);
  for (int f = 0; f < 50; ++f) EXPECT_EQ(run_frame(&b, &clock, 1.0, 0.3), 10) << "frame " << f;  // 4.075 ms
  EXPECT_EQ(b.changes(), 0);
  EXPECT_EQ(b.frames_over(), 0);
  EXPECT_EQ(b.frames_at()[0], 50);
  EXPECT_NEAR(b.predicted_ms(0), 1.0 + 0.3 * 10.25, 1e-9);
}

TEST(FrameBudget, DegradesWhenTheCostExceedsTheBudgetAndComesBackWhenTheLoadDrops) {
  FakeClock clock;
  FrameBudget b(8.0, budget_ladder(local_global(0)), &clock);
  // heavy load: 1 ms a unit makes 10 iterations (10.25 units) cost 11.25 ms; 6 iterations 7.25 ms hold 8 ms
  EXPECT_EQ(run_frame(&b, &clock, 1.0, 1.0), 10);
  EXPECT_EQ(b.frames_over(), 1);
  for (int f = 0; f < 30; ++f) EXPECT_EQ(run_frame(&b, &clock, 1.0, 1.0), 6) << "frame " << f;
  EXPECT_EQ(b.frames_over(), 1);
  // heavier: 1.8 ms a unit; 6 iterations cost 12.25 ms, 4 iterations would cost 8.65, 3 iterations (3.25 units)
  // 6.85 ms are the best that hold
  EXPECT_EQ(run_frame(&b, &clock, 1.0, 1.8), 6);
  EXPECT_EQ(run_frame(&b, &clock, 1.0, 1.8), 3);
  // the load drops to 0.3 ms a unit: the estimate falls gradually; back to 10 iterations once 1 + 10.25 u <= 6.4
  // (u <= 0.527, which the estimate 0.3 + (1.8 - 0.3) 0.8^k first reaches at k = 9) and not before the hold
  std::vector<int> ran;
  for (int f = 0; f < 40; ++f) ran.push_back(run_frame(&b, &clock, 1.0, 0.3));
  for (int f = 0; f < FrameBudget::kHoldFrames - 1; ++f) EXPECT_EQ(ran[f], 3) << "frame " << f;
  EXPECT_EQ(ran.back(), 10);
  int first_back = -1;
  for (int f = 0; f < 40 && first_back < 0; ++f)
    if (ran[f] == 10) first_back = f;
  EXPECT_EQ(first_back, 9);  // after the 9th cheap frame: k = 9, and 10 frames held at 3 iterations
  for (int f = first_back; f < 40; ++f) EXPECT_EQ(ran[f], 10);
  EXPECT_EQ(b.changes(), 3);
  EXPECT_EQ(b.frames_over(), 2);
}

TEST(FrameBudget, AFrameWhoseFixedPartAloneExceedsTheBudgetTakesTheCheapestSetting) {
  FakeClock clock;
  FrameBudget b(8.0, budget_ladder(local_global(0)), &clock);
  run_frame(&b, &clock, 9.0, 0.1);
  EXPECT_EQ(b.current(), static_cast<int>(b.ladder().size()) - 1);
  EXPECT_EQ(run_frame(&b, &clock, 9.0, 0.1), 1);
}

TEST(FrameBudget, FramesThatDoNotStepKeepTheStepEstimate) {
  FakeClock clock;
  FrameBudget b(8.0, budget_ladder(local_global(0)), &clock);
  run_frame(&b, &clock, 1.0, 0.5);
  const double before = b.predicted_ms(0);
  for (int f = 0; f < 5; ++f) {
    b.begin_frame();
    clock.t_ms += 1.0;
    b.end_frame();
  }
  EXPECT_DOUBLE_EQ(b.predicted_ms(0), before);
}

TEST(FrameBudget, AFrameThatSpendsItsBudgetBeforeTheStepStepsCheaper) {
  FakeClock clock;
  FrameBudget b(8.0, budget_ladder(local_global(0)), &clock);
  // 0.5 ms before and after the step, 0.3 ms a unit: 10 iterations cost 4.075 ms
  for (int f = 0; f < 20; ++f) ASSERT_EQ(run_frame(&b, &clock, 1.0, 0.3), 10);
  // a cutting frame: 5 ms spent before the step. At the planned 10 iterations it would take 5 + 3.075 + 0.5 = 8.575
  // ms; 6 iterations (6.25 units) make 7.375 ms, the most accurate rung that holds 8 ms
  EXPECT_EQ(b.current(), 0);
  EXPECT_NEAR(b.predicted_from_step_ms(0, 5.0), 8.575, 1e-9);
  EXPECT_EQ(run_frame(&b, &clock, 1.0, 0.3, 5.0), 6);
  EXPECT_EQ(b.frames_over(), 0);
  EXPECT_EQ(b.frames_stepped_cheaper(), 1);
  EXPECT_EQ(b.frames_at()[0], 20);
  EXPECT_EQ(b.frames_at()[1], 1);
  // the step's estimate per unit is that of the rung it stepped at: unchanged
  EXPECT_NEAR(b.predicted_from_step_ms(0, 0.5), 4.075, 1e-9);
  // 7.9 ms before the step leave no room for any rung: the cheapest (1 iteration) steps
  EXPECT_EQ(run_frame(&b, &clock, 1.0, 0.3, 7.9), 1);
  EXPECT_EQ(b.frames_stepped_cheaper(), 2);
}

// Planned to a fraction of the budget, the settings leave that much room: 1 ms a unit and 1 ms around the step,
// 6 iterations (7.25 ms) hold an 8 ms budget but not the 7 ms planned of it at 0.875, so 4 iterations (5.25 ms)
// run; a frame counts as over only past the budget itself. Climbing back needs kUpFraction of the plan.
TEST(FrameBudget, PlansToAFractionOfTheBudgetAndCountsOverOnlyPastTheBudget) {
  FakeClock clock;
  FrameBudget b(8.0, budget_ladder(local_global(0)), &clock, 0.875);
  EXPECT_DOUBLE_EQ(b.plan_ms(), 7.0);
  EXPECT_EQ(run_frame(&b, &clock, 1.0, 1.0), 10);  // unmeasured: the scene's setting, 11.25 ms
  EXPECT_EQ(b.frames_over(), 1);
  for (int f = 0; f < 20; ++f) EXPECT_EQ(run_frame(&b, &clock, 1.0, 1.0), 4) << "frame " << f;
  // a frame of 7.5 ms before its step would leave no rung within the plan: the cheapest steps, and the frame
  // (7.5 + 1.25 + 0.5 = 9.25 ms) is over the budget
  EXPECT_EQ(run_frame(&b, &clock, 1.0, 1.0, 7.5), 1);
  EXPECT_EQ(b.frames_over(), 2);
  // 0.6 ms a unit: 4 iterations cost 3.55 ms; 6 iterations 4.75 ms are within 0.8 of the 7 ms plan (5.6), 10
  // iterations 7.15 ms are not: after the hold, the ladder climbs to 6 and stays
  std::vector<int> ran;
  for (int f = 0; f < 60; ++f) ran.push_back(run_frame(&b, &clock, 1.0, 0.6));
  EXPECT_EQ(ran.back(), 6);
  EXPECT_EQ(std::count(ran.begin(), ran.end(), 10), 0);
  // with the whole budget planned (the default), 6 iterations at 1 ms a unit (7.25 ms) hold it
  FrameBudget whole(8.0, budget_ladder(local_global(0)), &clock);
  EXPECT_DOUBLE_EQ(whole.plan_ms(), 8.0);
  EXPECT_EQ(run_frame(&whole, &clock, 1.0, 1.0), 10);
  EXPECT_EQ(run_frame(&whole, &clock, 1.0, 1.0), 6);  // 7.25 ms hold 8 ms
}

}  // namespace
}  // namespace palpate
