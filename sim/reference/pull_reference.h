#pragma once
/// The large-strain pull reference of `palpate bench model`: a cube glued to the floor and, over the middle of its
/// top, to a square handle (by default the whole top: a plate) pulled straight up 40 mm, run to rest in increments by
/// the lattice's own integrator (sim/reference/settle.h). No closed form exists (the glued faces keep the block from
/// narrowing there), so the handle's force at three levels is checked against their Richardson extrapolation
/// (sim/reference/richardson.h). A handle narrower than the top has a singular edge and converges slowly (order ~0.1 here).

#include "core/result.h"
#include "core/scene.h"
#include "sim/reference/settle.h"

namespace palpate {

/// Geometry of the pull. Plain data.
struct PullGeometry {
  double block_m = 0.08;      ///< side of the cube block (a grid cube: cells of block_m / 2^(level-1))
  double handle_m = 0.08;     ///< side of the square handle on the top's middle (the whole top by default)
  double pull_m = 0.04;       ///< how far the handle goes up
  int increments = 8;         ///< equal steps of the pull, each run to rest
};

/// What one level gives.
struct PullCheck {
  double force_N = 0.0;        ///< the handle's pull at the end (the lattice's reaction on its nodes, +z)
  std::size_t nodes = 0;       ///< lattice nodes
  std::size_t springs = 0;     ///< lattice springs
  std::size_t handle_nodes = 0;  ///< nodes glued to the handle
  SettleReport settle;         ///< frames over all increments, the slowest increment's CPU ms per frame
};

/// Pulls the block of `material` at `level` (>= 3: the handle spans a cell) and returns the handle's force.
/// Errors name the level and the increment that did not come to rest.
Result<PullCheck> check_pull(const MaterialSpec& material, int level, const PullGeometry& geometry = {},
                             const SettleOptions& settle = {});

}  // namespace palpate
