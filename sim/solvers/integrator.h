#pragma once
/// Time integration of the lattice, one entry point for every scheme: the paper's explicit Euler (eq. 8),
/// symplectic Euler and RK4 with automatic substeps, implicit Euler (Newton, matrix-free conjugate gradients) and a
/// Liu-2013-style local/global solver with a prefactored system matrix.

#include <cstdint>
#include <memory>
#include <vector>

#include "core/scene.h"
#include "sim/lattice/lattice.h"
#include "sim/solvers/stability.h"

namespace palpate {

class ImplicitEulerSolver;
class LocalGlobalSolver;

/// How to step: scheme, substeps, iterations, strain limit. Plain data; copyable.
struct StepOptions {
  IntegratorKind kind = IntegratorKind::kSymplecticEuler;  ///< scheme
  int substeps = 0;        ///< fixed substeps per step; 0 = automatic (explicit/symplectic/rk4: stability bound, else 1)
  int max_substeps = 256;  ///< cap on automatic substeps
  int iterations = 0;      ///< Newton / local-global iterations per substep; 0 = default (1 Newton, 10 local-global)
  double strain_limit = 0.0;  ///< > 0: after each substep springs are projected into rest * [1 - s, 1 + s]
  /// > 0: a monotonic time (core/clock.h, monotonic_ns) past which an implicit substep that failed whole is not
  /// retried further (its splits, its projected Newton steps): the step ends there, the lattice keeping the state it
  /// reached (a realtime frame's deadline; 0 in lockstep, where every step is taken whatever it costs)
  int64_t deadline_ns = 0;
};

/// The step options a scene asks for.
StepOptions step_options(const LatticeSpec& spec);

/// What one step did.
struct StepReport {
  int substeps = 0;         ///< substeps taken
  int iterations = 0;       ///< solver iterations over all substeps (Newton or local/global; 0 for explicit schemes)
  int cg_iterations = 0;    ///< implicit Euler: conjugate gradient iterations over all its Newton solves (else 0)
  bool finite = true;       ///< false when the state went non-finite (the caller resets it)
  bool diverged = false;    ///< non-finite, or a spring stretched past kDivergedStrain (the caller resets it)
  int implicit_splits = 0;  ///< implicit Euler substeps that failed whole and were taken again in pieces
  int projected_steps = 0;  ///< implicit Euler substeps that failed in every split too and were taken by projected Newton
  bool solver_ok = true;    ///< false when a linear solve or factorisation failed (implicit Euler: in every split and the projected Newton step too; the step then fell back to symplectic Euler)
  double max_strain = 0.0;  ///< largest |l - l0| / l0 after the step
  bool out_of_time = false; ///< StepOptions::deadline_ns passed in a substep's retries: the step ended early
};

/// Local/global iterations per substep when StepOptions::iterations is 0.
inline constexpr int kDefaultLocalGlobalIterations = 10;

/// A spring strained beyond this (l > 11 l0) is taken as divergence, not deformation.
inline constexpr double kDivergedStrain = 10.0;

/// Scratch buffers and solver caches reused across steps; caches key on Lattice::revision and the substep.
/// Move-only. Thread: the one stepping thread.
struct IntegratorWorkspace {
  IntegratorWorkspace();
  ~IntegratorWorkspace();
  IntegratorWorkspace(IntegratorWorkspace&&) noexcept;
  IntegratorWorkspace& operator=(IntegratorWorkspace&&) noexcept;

  std::vector<Vec3> f_N;                        ///< forces (n)
  std::vector<Vec3> x0_m, v0_m_per_s;           ///< state at the start of a substep (n)
  std::vector<Vec3> acc_x, acc_v;               ///< RK4 accumulators (n)
  std::vector<Vec3> stage_x, stage_v;           ///< RK4 stage state (n)
  std::unique_ptr<ImplicitEulerSolver> implicit;     ///< created on first use
  std::unique_ptr<LocalGlobalSolver> local_global;   ///< created on first use
  uint64_t bound_revision = 0;                  ///< Lattice::revision the cached bound belongs to (0 = none)
  StabilityBound bound;                         ///< stability_bound(lat, 0.8), recomputed only when the revision changes
};

/// Advances the lattice by dt_s with opts. f_ext_N (n, or empty) is held constant over the step.
/// Fixed nodes stay at rest. Never throws; bad states are reported, not hidden.
StepReport step_lattice(Lattice* lat, const StepOptions& opts, double dt_s, const std::vector<Vec3>& f_ext_N,
                        IntegratorWorkspace* ws);

/// Builds what the next step_lattice() with these options would build first (local/global: its factorisation),
/// so that cost is paid now; the lattice's state is not touched.
void prepare_step(const Lattice& lat, const StepOptions& opts, double dt_s, IntegratorWorkspace* ws);

/// Shorthand: automatic substeps (capped at max_substeps), default iterations, no strain limit.
StepReport step_lattice(Lattice* lat, IntegratorKind kind, double dt_s, int max_substeps,
                        const std::vector<Vec3>& f_ext_N, IntegratorWorkspace* ws);

/// Substeps the scheme takes for dt_s under opts (automatic ones from stability_bound with safety 0.8).
int substeps_for(const Lattice& lat, const StepOptions& opts, double dt_s);

/// The same, with the bound cached in ws on the lattice's revision (no allocation and no sweep once cached).
int substeps_for(const Lattice& lat, const StepOptions& opts, double dt_s, IntegratorWorkspace* ws);

/// stability_bound(lat, 0.8) cached in ws on the lattice's revision: mass, stiffness and topology changes touch() it.
const StabilityBound& cached_stability_bound(const Lattice& lat, IntegratorWorkspace* ws);

}  // namespace palpate
