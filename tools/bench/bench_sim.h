#pragma once
/// `palpate bench sim`: replays a scene's interaction in lockstep for every integrator x lattice level x
/// substeps/iterations and reports speed against error relative to a converged RK4 reference.

#include <string>
#include <vector>

#include "core/result.h"
#include "core/scene.h"
#include "tools/bench/plot.h"

namespace palpate {

/// What to sweep and where to write. Plain data.
struct BenchSimOptions {
  std::vector<std::string> integrators;  ///< names; empty = all five
  std::vector<int> levels;               ///< lattice levels; empty = the scene's
  std::vector<int> substeps{0};          ///< fixed substeps per frame; 0 = automatic
  std::vector<int> iterations{0};        ///< Newton / local-global iterations (implicit schemes only); 0 = default
  int reference_substeps = 64;           ///< RK4 substeps per frame of the reference (checked against half as many)
  double duration_s = 0.0;               ///< > 0 overrides the scene's duration
  std::string json_path;                 ///< write JSON here when not empty
  std::string plot_path;                 ///< the error-against-ms plot goes here (FILE.png, FILE.dat, FILE.gp)
  bool quiet = false;                    ///< no progress lines on stderr
  std::vector<int> box_cells;            ///< not empty: box lattices of these cells per axis instead of the scene's replay
};

/// The integrators `names` lists, or `all` when it is empty; errors name an unknown one.
Result<std::vector<IntegratorKind>> integrators_from_names(const std::vector<std::string>& names,
                                                           std::vector<IntegratorKind> all);

/// Runs the sweep; returns the table as text, and when `plot` is given and options.plot_path is set fills it with
/// the figure (node error against ms per frame, log axes, per integrator, Pareto front per level) for the caller
/// to draw after printing the table. Errors name the scene, an unknown integrator or an output path.
Result<std::string> run_bench_sim(const std::string& scene_path, const BenchSimOptions& options, PlotSpec* plot = nullptr);

/// Steps box lattices (options.box_cells per axis, powers of two; the scene's k, m, c, floor fixed) under a pull on
/// the top face for every integrator x substeps x iterations and reports step ms per frame (p50, p99, ratio to
/// symplectic Euler with automatic substeps) and node error against an RK4 reference (duration default 1 s).
/// Errors name the scene, an unknown integrator or a box size that is not a power of two.
Result<std::string> run_bench_sim_box(const std::string& scene_path, const BenchSimOptions& options);

}  // namespace palpate
