#pragma once
/// LatticeStepper: a frame's step of the lattice. It steps at the scene's step options, or, with lattice.budget_ms,
/// at the rung of the budget's ladder predicted to hold the budget; in realtime each step ends at the frame's
/// deadline; a lattice at rest is not stepped until a force acts. A diverged step is counted and the lattice put
/// back to rest, so the run goes on. Owns the integrator's workspace; its figures go into FrameStats and the frame's
/// profile. Thread: the sim thread only.

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "core/scene.h"
#include "runtime/session/frame_stats.h"
#include "sim/solvers/frame_budget.h"
#include "sim/solvers/integrator.h"
#include "sim/lattice/lattice.h"

namespace palpate {

class LatticeStepper {
 public:
  /// scene and stats must outlive it.
  LatticeStepper(const Scene& scene, FrameStats* stats);
  /// Keeps lattice.budget_ms with the frame's cost read from `clock` (which must outlive it). False, and no budget,
  /// when the scene sets none or its integrator has nothing to trade.
  bool use_budget(BudgetClock* clock);
  /// Realtime: every step has a deadline a frame period after its frame began.
  void keep_deadlines() { deadlines_ = true; }
  const FrameBudget* budget() const { return budget_ ? &*budget_ : nullptr; }
  /// The solver's factorisation of lat at the scene's options, before the first frame's deadline (a lattice built
  /// up front: the same factor its first step would make).
  void prepare(Lattice* lat);
  /// One step of a copy of lat at the budget's first rung, on its clock, seeds the budget (once; lat is untouched:
  /// the copy has its revision, so the solver uses the factor it holds). No effect without a budget.
  void seed_budget(const Lattice& lat);
  /// A frame begins (monotonic ns) and ends.
  void begin_frame(int64_t start_ns);
  void end_frame();
  /// The lattice changed: it steps again even without a force.
  void wake() { resting_ = false; }
  /// Steps `lat` unless it rests and no force pushes it. whole_f_ext: the whole lattice's node forces; lat is the
  /// whole lattice (whole true), which takes them, or a part of it, which takes none. lap(part) is called after
  /// the factorisation and after the step; bound_vertices counts into the figures. True when it stepped.
  bool step(Lattice* lat, bool whole, const std::vector<Vec3>& whole_f_ext, std::size_t bound_vertices,
            FrameProfile* profile, const std::function<void(FramePart)>& lap);

 private:
  const Scene& scene_;
  FrameStats* stats_;
  IntegratorWorkspace ws_;
  StepOptions step_opts_;                    // from the scene, fixed for the run
  std::optional<FrameBudget> budget_;        // lattice.budget_ms: picks the step options of each frame
  const StepOptions* frame_opts_ = nullptr;  // this frame's options (the budget's), else step_opts_
  ThreadCpuClock cpu_clock_;                 // for the step's CPU time
  bool resting_ = false;                     // the lattice is at rest: not stepped until a force acts
  bool deadlines_ = false;
  bool seeded_ = false;
  int64_t frame_start_ns_ = 0;
  std::vector<Vec3> rest_scratch_;           // forces for the rest check (n)
  std::vector<Vec3> part_f_ext_N_;           // zero forces on a stepped part of the lattice (n_part)
};

}  // namespace palpate
