#pragma once
/// Equilibrium by the simulation itself: a lattice stepped frame by frame with one of its integrators under a
/// constant load until it is at rest. The rest state of a damped run is the static equilibrium of the lattice's
/// springs (sim/solvers/static_solve.h computes the same state directly, as a cross-check).

#include <cstdint>
#include <vector>

#include "core/rates.h"
#include "core/result.h"
#include "sim/solvers/integrator.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// Integrator, frame length and the rest test. Plain data.
struct SettleOptions {
  StepOptions step;                 ///< the integrator and its substeps (kind default: implicit Euler)
  double frame_s = 1.0 / kDefaultFrameRate_hz;      ///< one step_lattice call
  int max_frames = 20000;           ///< error past this many frames
  double rest_rel = 1e-5;           ///< at rest: the largest free node's force imbalance below rest_rel x the largest
                                    ///< load on a node, and no node moving more than rest_rel x the largest
                                    ///< displacement from rest per frame
  SettleOptions() { step.kind = IntegratorKind::kImplicitEuler; }
};

/// What the run took.
struct SettleReport {
  int frames = 0;                   ///< frames stepped until at rest
  int64_t substeps = 0;             ///< integrator substeps over them
  double ms_per_frame_p50 = 0.0;    ///< thread CPU time of one frame (median; wall time swings with other load)
  double residual_rel = 0.0;        ///< force imbalance at the end, over the largest nodal load
};

/// Steps *lat from its current state under f_ext_N (n) and gravity until at rest; lat->fixed nodes and lat->held_dof
/// stay put (the force on those is a support's reaction and does not count against rest).
/// Errors when the state diverges or max_frames pass first, naming the frame and the imbalance.
Result<SettleReport> settle(Lattice* lat, const std::vector<Vec3>& f_ext_N, const SettleOptions& options = {});

/// Net force on every node at rest (springs, gravity and f_ext_N; the nodes' reactions where they are fixed).
std::vector<Vec3> net_static_forces_N(const Lattice& lat, const std::vector<Vec3>& f_ext_N);

}  // namespace palpate
