#include "sim/reference/pull_reference.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "sim/reference/reference_cases.h"
#include "sim/solvers/static_solve.h"

namespace palpate {

Result<PullCheck> check_pull(const MaterialSpec& material, int level, const PullGeometry& g,
                             const SettleOptions& settle_options) {
  const int n = 1 << (level - 1);
  const double l = g.block_m / n;
  if (!(g.handle_m >= l))
    return make_error("pull: the handle (", std::to_string(g.handle_m), " m) is narrower than a cell (",
                      std::to_string(l), " m) at level ", std::to_string(level));
  auto built = box_lattice(material, g.block_m, level, {n, n, n});
  if (!built) return built.error();
  Lattice& L = built.value();
  const std::size_t nodes = L.num_nodes();
  const double side = g.block_m, half = 0.5 * side, eps = 1e-9 * side, h = 0.5 * g.handle_m;
  // the floor and the handle's nodes fixed; how far each node lies outside the handle's square, sideways
  std::vector<std::size_t> handle;
  std::vector<double> outside_m(nodes, 0.0);
  for (std::size_t i = 0; i < nodes; ++i) {
    const Vec3& r = L.rest_m[i];
    outside_m[i] = std::max({std::abs(r.x() - half) - h, std::abs(r.y() - half) - h, 0.0});
    if (r.z() < eps) L.fixed[i] = 1;
    if (r.z() > side - eps && outside_m[i] < eps) {
      L.fixed[i] = 1;
      handle.push_back(i);
    }
  }
  L.touch();
  PullCheck out;
  const double step_m = g.pull_m / g.increments;
  for (int k = 1; k <= g.increments; ++k) {
    // the handle up by a step; the rest moved along as a first guess (with height, fading away from the handle),
    // narrowing between the glued faces as much as keeps its volume (a nearly incompressible cell stretched in z
    // only would burst)
    const double narrow = std::sqrt((side + (k - 1) * step_m) / (side + k * step_m));
    for (std::size_t i = 0; i < nodes; ++i) {
      const Vec3& r = L.rest_m[i];
      if (r.z() < eps) continue;
      const double fade = std::max(0.0, 1.0 - outside_m[i] / side);
      L.x_m[i].z() += step_m * (L.fixed[i] ? 1.0 : r.z() / side * fade);
      if (L.fixed[i]) continue;
      const double waist = 1.0 + (narrow - 1.0) * fade * 4.0 * r.z() * (side - r.z()) / (side * side);
      L.x_m[i].x() = half + (L.x_m[i].x() - half) * waist;
      L.x_m[i].y() = half + (L.x_m[i].y() - half) * waist;
    }
    auto rep = settle(&L, {}, settle_options);
    if (!rep)
      return make_error("pull level ", std::to_string(level), ", increment ", std::to_string(k), " of ",
                        std::to_string(g.increments), ": ", rep.error().message);
    out.settle.frames += rep.value().frames;
    out.settle.substeps += rep.value().substeps;
    out.settle.ms_per_frame_p50 = std::max(out.settle.ms_per_frame_p50, rep.value().ms_per_frame_p50);
    out.settle.residual_rel = rep.value().residual_rel;
  }
  const std::vector<Vec3> f = spring_forces_N(L, L.x_m);
  for (std::size_t i : handle) out.force_N -= f[i].z();
  out.nodes = nodes;
  out.springs = L.springs.size();
  out.handle_nodes = handle.size();
  return out;
}

}  // namespace palpate
