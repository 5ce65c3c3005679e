#include <algorithm>

#include "core/thread_cpu.h"
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <ctime>
#include <vector>

#include "core/grid_hierarchy.h"
#include "core/rates.h"
#include "core/limits.h"
#include "core/scene.h"
#include "core/stats.h"
#include "sim/lattice/forces.h"
#include "sim/solvers/integrator.h"
#include "sim/lattice/lattice.h"
#include "tools/bench/bench_sim.h"

namespace palpate {
namespace {

constexpr double kFrameRate_hz = kDefaultFrameRate_hz;  // the scenes' frame rate when they do not say (core/rates.h)
constexpr double kBoxSide_m = 0.1;         // the bunny's size_m
constexpr double kPullTotal_N = 0.3;       // spread over the top face's 3 x 3 centre nodes
constexpr double kPullRamp_s = 0.25;       // force ramps up over this ...
constexpr double kPullRelease_s = 0.5;     // ... and is released here; the rest of the run rings down

// A lattice over every cell of a cube split into `cells` per axis (a power of two), floor fixed.
Result<Lattice> box_lattice(const LatticeSpec& spec_in, int cells) {
  // the lattice's size is known from the option alone: refused before any grid or lattice exists
  const int64_t nodes = int64_t{cells + 1} * (cells + 1) * (cells + 1);
  if (nodes > kMaxLatticeNodes)
    return make_error("bench sim: --box ", std::to_string(cells), " makes ", std::to_string(nodes),
                      " nodes, more than the limit of ", std::to_string(kMaxLatticeNodes));
  int level = 1;
  while ((1 << (level - 1)) < cells) ++level;
  if ((1 << (level - 1)) != cells || level > GridHierarchy::kMaxLevels)
    return make_error("bench sim: --box ", std::to_string(cells), " is not a power of two in [1, 128]");
  TriMesh cube;
  for (int c = 0; c < 8; ++c) cube.vertices_m.push_back(kBoxSide_m * Vec3(c & 1, (c >> 1) & 1, (c >> 2) & 1));
  // 12 triangles, outward winding not needed by the grid (it only tests overlap)
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    cube.triangles.push_back({f[0], f[1], f[2]});
    cube.triangles.push_back({f[0], f[2], f[3]});
  }
  Aabb box;
  box.max_m = Vec3::Constant(kBoxSide_m);
  auto grid_r = GridHierarchy::build(cube, box, level);
  if (!grid_r) return grid_r.error();
  LatticeSpec spec = spec_in;
  spec.level = level;
  spec.fix_floor = true;
  std::vector<int32_t> all(static_cast<std::size_t>(grid_r.value().num_cells(level)));
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int32_t>(i);
  return build_lattice(grid_r.value(), spec, all);
}

// The pull: +z on the top face's centre nodes, ramped, held, released.
void pull_force(const Lattice& lat, double t_s, std::vector<Vec3>* f_ext_N) {
  f_ext_N->assign(lat.num_nodes(), Vec3::Zero());
  if (t_s >= kPullRelease_s) return;
  const double mag = kPullTotal_N * std::min(1.0, t_s / kPullRamp_s) / 9.0;
  const Vec3 centre(0.5 * kBoxSide_m, 0.5 * kBoxSide_m, kBoxSide_m);
  for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
    const Vec3 d = lat.rest_m[i] - centre;
    if (std::abs(d.z()) < 1e-9 && std::abs(d.x()) <= 1.01 * lat.cell_m && std::abs(d.y()) <= 1.01 * lat.cell_m)
      (*f_ext_N)[i] = Vec3(0.0, 0.0, mag);
  }
}

struct BoxRun {
  std::vector<std::vector<Vec3>> x_m;  // per frame: node positions
  std::vector<double> step_ms;         // per frame, wall clock
  std::vector<double> cpu_ms;          // per frame, thread CPU time
  int max_substeps = 0;
  int iterations = 0;                  // solver iterations, summed over frames
  bool stable = true;
  double max_strain = 0.0;
};

BoxRun run_box(const Lattice& start, const StepOptions& opts, int frames) {
  Lattice lat = start;
  IntegratorWorkspace ws;
  std::vector<Vec3> f_ext_N;
  BoxRun r;
  r.x_m.reserve(static_cast<std::size_t>(frames));
  r.step_ms.reserve(static_cast<std::size_t>(frames));
  r.cpu_ms.reserve(static_cast<std::size_t>(frames));
  for (int f = 0; f < frames; ++f) {
    pull_force(lat, f / kFrameRate_hz, &f_ext_N);
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = thread_cpu_ms();
    const StepReport rep = step_lattice(&lat, opts, 1.0 / kFrameRate_hz, f_ext_N, &ws);
    r.cpu_ms.push_back(thread_cpu_ms() - c0);
    r.step_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    r.max_substeps = std::max(r.max_substeps, rep.substeps);
    r.iterations += rep.iterations;
    r.stable = r.stable && !rep.diverged && rep.solver_ok;
    r.max_strain = std::max(r.max_strain, max_strain(lat));
    r.x_m.push_back(lat.x_m);
  }
  return r;
}

// RMS and max node distance between two runs over all frames, in cells.
std::pair<double, double> node_error(const BoxRun& run, const BoxRun& ref, double cell_m) {
  double sum = 0.0, worst = 0.0;
  int64_t count = 0;
  for (std::size_t f = 0; f < std::min(run.x_m.size(), ref.x_m.size()); ++f)
    for (std::size_t i = 0; i < ref.x_m[f].size(); ++i) {
      const double d = (run.x_m[f][i] - ref.x_m[f][i]).norm();
      sum += d * d;
      worst = std::max(worst, d);
      ++count;
    }
  const double rms = count ? std::sqrt(sum / static_cast<double>(count)) : 0.0;
  return {rms / cell_m, worst / cell_m};
}

}  // namespace

Result<std::string> run_bench_sim_box(const std::string& scene_path, const BenchSimOptions& opt) {
  // refused before the sweep rather than skipped after it: there is no box figure
  if (!opt.plot_path.empty())
    return make_error("bench sim: --plot draws the scene replay's sweep; --box has no plot (its figures are in the "
                      "table and --json)");
  auto scene_r = load_scene(scene_path);
  if (!scene_r) return scene_r.error();
  const Scene& scene = scene_r.value();
  auto kinds_r = integrators_from_names(opt.integrators, {IntegratorKind::kSymplecticEuler, IntegratorKind::kImplicitEuler,
                                                          IntegratorKind::kLocalGlobal, IntegratorKind::kRk4});
  if (!kinds_r) return kinds_r.error();
  const std::vector<IntegratorKind> kinds = kinds_r.value();
  const double duration_s = opt.duration_s > 0.0 ? opt.duration_s : 1.0;
  const int frames = std::max(1, static_cast<int>(std::lround(duration_s * kFrameRate_hz)));

  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-17s %5s %4s %4s | %8s %8s %8s %7s | %9s %9s | %7s %6s\n", "integrator", "nodes",
                "sub", "iter", "step p50", "step p99", "cpu p50", "/ sympl", "node rms", "node max", "strain", "stable");
  out += line;
  for (int cells : opt.box_cells) {
    auto lat_r = box_lattice(scene.lattice, cells);
    if (!lat_r) return lat_r.error();
    const Lattice& lat = lat_r.value();
    StepOptions ro = step_options(scene.lattice);
    ro.kind = IntegratorKind::kRk4;
    ro.substeps = opt.reference_substeps;
    if (!opt.quiet) std::fprintf(stderr, "bench sim: box %d^3 (%zu nodes) reference\n", cells, lat.num_nodes());
    const BoxRun ref = run_box(lat, ro, frames);
    double symplectic_cpu50 = 0.0;
    struct Line {
      std::string name;
      int sub, it, max_sub;
      double p50, p99, cpu50, rms, max, strain;
      bool stable;
    };
    std::vector<Line> lines;
    for (IntegratorKind kind : kinds)
      for (int sub : opt.substeps)
        for (int it : (kind == IntegratorKind::kImplicitEuler || kind == IntegratorKind::kLocalGlobal
                           ? opt.iterations : std::vector<int>{0})) {
          StepOptions o = step_options(scene.lattice);
          o.kind = kind;
          o.substeps = sub;
          o.iterations = it;
          if (!opt.quiet)
            std::fprintf(stderr, "bench sim: box %d^3 %s substeps %d iterations %d\n", cells, integrator_name(kind), sub, it);
          const BoxRun run = run_box(lat, o, frames);
          const auto [rms, worst] = node_error(run, ref, lat.cell_m);
          const double p50 = percentile(run.step_ms, 0.5), cpu50 = percentile(run.cpu_ms, 0.5);
          if (kind == IntegratorKind::kSymplecticEuler && sub == 0) symplectic_cpu50 = cpu50;
          lines.push_back({integrator_name(kind), sub, it, run.max_substeps, p50, percentile(run.step_ms, 0.99), cpu50, rms,
                           worst, run.max_strain, run.stable});
        }
    for (const Line& l : lines) {
      char sub[32];
      std::snprintf(sub, sizeof sub, l.sub ? "%d" : "a%d", l.sub ? l.sub : l.max_sub);
      char ratio[32] = "-";
      if (symplectic_cpu50 > 0.0) std::snprintf(ratio, sizeof ratio, "%.1f", l.cpu50 / symplectic_cpu50);
      std::snprintf(line, sizeof line, "%-17s %5zu %4s %4s | %8.3f %8.3f %8.3f %7s | %9.2e %9.2e | %7.3f %6s\n",
                    l.name.c_str(), lat.num_nodes(), sub, l.it ? std::to_string(l.it).c_str() : "-", l.p50,
                    l.p99, l.cpu50, ratio, l.rms, l.max, l.strain, l.stable ? "yes" : "NO");
      out += line;
    }
  }
  std::snprintf(line, sizeof line,
                "box lattices of the scene's k, m, c (floor fixed), %d frames of 1/60 s, %.2f N pulling the top centre "
                "(ramp %.2f s, release %.2f s); step ms per frame (wall p50, p99; thread CPU p50 and "
                "its ratio to symplectic_euler's at automatic substeps); errors in cells against rk4 x%d substeps; "
                "sub aN = automatic, at most N\n",
                frames, kPullTotal_N, kPullRamp_s, kPullRelease_s, opt.reference_substeps);
  out += line;
  return out;
}

}  // namespace palpate
