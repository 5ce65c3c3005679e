#include "tools/bench/bench_sim.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/scene.h"
#include "core/stats.h"
#include "sim/lattice/forces.h"
#include "tools/bench/plot.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/model.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {

// Everything one lockstep replay leaves behind for comparison.
struct Trace {
  std::vector<std::unordered_map<int32_t, Vec3>> nodes_m;  // per frame: grid node -> position
  std::vector<std::vector<Vec3>> vertices_m;               // per frame: the whole mesh
  std::vector<Vec3> force_N;                               // per servo tick: force sent to the device
  std::vector<double> energy_J;                            // per frame: lattice energy (0 before contact)
  double max_strain = 0.0;
  double cell_m = 0.0;
  FrameStats stats;
};

// Replays the scene's interaction through the real servo and frame stage (no rendering), in lockstep.
Result<Trace> replay(const Scene& scene, const Model& model) {
  auto device_r = make_device(scene, "");
  if (!device_r) return device_r.error();
  // the session as `palpate record` wires it, at the scene's rates; every configuration gets the same servo
  Session session(scene, model, device_r.value().get());
  const FrameStage& stage = session.stage();
  Trace t;
  t.force_N.reserve(static_cast<std::size_t>(scene.rates.ticks(scene.duration_s)));
  auto after_frame = [&]() {
    std::unordered_map<int32_t, Vec3> nodes;
    double e = 0.0;
    if (const auto& lat = stage.lattice()) {
      for (std::size_t i = 0; i < lat->num_nodes(); ++i) nodes.emplace(lat->grid_node[i], lat->x_m[i]);
      e = lattice_energy_J(*lat);
      t.max_strain = std::max(t.max_strain, max_strain(*lat));
      t.cell_m = lat->cell_m;
    }
    t.nodes_m.push_back(std::move(nodes));
    t.vertices_m.push_back(stage.vertices_m());
    t.energy_J.push_back(e);
  };
  session.run_lockstep(
      scene.duration_s, [&](int64_t, double) { after_frame(); },
      [&](int64_t, double) { t.force_N.push_back(session.servo().last_sample().force_N); });
  t.stats = stage.stats();
  return t;
}

// Errors of a run against the reference.
struct Errors {
  double node_rms = 0.0, node_max = 0.0;  // / cell
  double vertex_rms = 0.0;                // / cell
  double force_rms_N = 0.0;
  double energy_drift = 0.0;              // max |E - E_ref| / max E_ref
};

Errors compare(const Trace& run, const Trace& ref, const Model& model) {
  Errors e;
  const double cell = ref.cell_m > 0.0 ? ref.cell_m : 1.0;
  double sum = 0.0;
  int64_t count = 0;
  for (std::size_t f = 0; f < std::min(run.nodes_m.size(), ref.nodes_m.size()); ++f) {
    // nodes simulated in either run; a node one run does not simulate is at rest there
    auto pos = [&](const std::unordered_map<int32_t, Vec3>& m, int32_t g, const Vec3& fallback) {
      const auto it = m.find(g);
      return it == m.end() ? fallback : it->second;
    };
    for (const auto& [g, x_ref] : ref.nodes_m[f]) {
      const double d = (pos(run.nodes_m[f], g, x_ref) - x_ref).norm();
      sum += d * d;
      ++count;
      e.node_max = std::max(e.node_max, d);
    }
  }
  e.node_rms = count ? std::sqrt(sum / static_cast<double>(count)) / cell : 0.0;
  e.node_max /= cell;
  // vertices the reference moved at some time
  std::vector<int32_t> moved;
  for (std::size_t v = 0; v < model.rest.vertices_m.size(); ++v)
    for (const auto& frame : ref.vertices_m)
      if (frame[v] != model.rest.vertices_m[v]) {
        moved.push_back(static_cast<int32_t>(v));
        break;
      }
  sum = 0.0;
  count = 0;
  for (std::size_t f = 0; f < std::min(run.vertices_m.size(), ref.vertices_m.size()); ++f)
    for (int32_t v : moved) {
      sum += (run.vertices_m[f][v] - ref.vertices_m[f][v]).squaredNorm();
      ++count;
    }
  e.vertex_rms = count ? std::sqrt(sum / static_cast<double>(count)) / cell : 0.0;
  sum = 0.0;
  for (std::size_t i = 0; i < std::min(run.force_N.size(), ref.force_N.size()); ++i)
    sum += (run.force_N[i] - ref.force_N[i]).squaredNorm();
  e.force_rms_N = ref.force_N.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(ref.force_N.size()));
  double e_max = 0.0, d_max = 0.0;
  for (std::size_t f = 0; f < std::min(run.energy_J.size(), ref.energy_J.size()); ++f) {
    e_max = std::max(e_max, std::abs(ref.energy_J[f]));
    d_max = std::max(d_max, std::abs(run.energy_J[f] - ref.energy_J[f]));
  }
  e.energy_drift = e_max > 0.0 ? d_max / e_max : 0.0;
  return e;
}

struct Row {
  std::string integrator;
  int level = 0, substeps = 0, iterations = 0;
  double frame_ms_p50 = 0, frame_ms_p99 = 0, step_ms_p50 = 0, step_ms_p99 = 0;
  double nodes_per_s = 0, springs_per_s = 0;
  Errors err;
  double max_strain = 0;
  int max_substeps_taken = 0;
  bool stable = true;
};

bool uses_iterations(IntegratorKind k) { return k == IntegratorKind::kImplicitEuler || k == IntegratorKind::kLocalGlobal; }

// Pareto front (lower ms and lower error) of the stable rows at one level (errors at different levels are
// against different references), sorted by ms.
std::vector<std::size_t> pareto(const std::vector<Row>& rows, int level) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < rows.size(); ++i)
    if (rows[i].stable && rows[i].level == level) idx.push_back(i);
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return rows[a].frame_ms_p50 < rows[b].frame_ms_p50; });
  std::vector<std::size_t> front;
  double best = INFINITY;
  for (std::size_t i : idx)
    if (rows[i].err.node_rms < best) {
      best = rows[i].err.node_rms;
      front.push_back(i);
    }
  return front;
}

}  // namespace

Result<std::vector<IntegratorKind>> integrators_from_names(const std::vector<std::string>& names,
                                                           std::vector<IntegratorKind> all) {
  if (names.empty()) return all;
  std::vector<IntegratorKind> kinds;
  for (const auto& name : names) {
    IntegratorKind k;
    if (!integrator_from_name(name, &k)) return make_error("bench sim: unknown integrator '", name, "'");
    kinds.push_back(k);
  }
  return kinds;
}

Result<std::string> run_bench_sim(const std::string& scene_path, const BenchSimOptions& opt, PlotSpec* plot) {
  // outputs are checked before the sweep: never a device or a link replaced after minutes of measuring
  if (!opt.json_path.empty())
    if (auto st = check_output_target(opt.json_path, "bench json"); !st) return st.error();
  if (!opt.plot_path.empty())
    if (auto st = check_plot_targets(opt.plot_path); !st) return st.error();
  auto scene_r = load_scene(scene_path);
  if (!scene_r) return scene_r.error();
  Scene base = scene_r.value();
  if (opt.duration_s > 0.0) base.duration_s = opt.duration_s;
  auto kinds_r = integrators_from_names(opt.integrators,
                                        {IntegratorKind::kExplicitEuler, IntegratorKind::kSymplecticEuler,
                                         IntegratorKind::kImplicitEuler, IntegratorKind::kLocalGlobal, IntegratorKind::kRk4});
  if (!kinds_r) return kinds_r.error();
  const std::vector<IntegratorKind> kinds = kinds_r.value();
  std::vector<int> levels = opt.levels.empty() ? std::vector<int>{base.lattice.level} : opt.levels;
  for (int l : levels)
    if (l < 1 || l > GridHierarchy::kMaxLevels) return make_error("bench sim: level ", std::to_string(l), " out of range [1, 8]");

  std::vector<Row> rows;
  nlohmann::json refs = nlohmann::json::array();
  for (int level : levels) {
    Scene s = base;
    s.lattice.level = level;
    s.grid_levels = std::max(s.grid_levels, level);
    auto model_r = load_model(s);
    if (!model_r) return model_r.error();
    const Model& model = model_r.value();
    // the converged reference: RK4 at many fixed substeps, checked against half as many
    Scene rs = s;
    rs.lattice.integrator = IntegratorKind::kRk4;
    rs.lattice.substeps = opt.reference_substeps;
    if (!opt.quiet) std::fprintf(stderr, "bench sim: level %d reference (rk4, %d substeps)\n", level, opt.reference_substeps);
    auto ref_r = replay(rs, model);
    if (!ref_r) return ref_r.error();
    rs.lattice.substeps = std::max(1, opt.reference_substeps / 2);
    auto half_r = replay(rs, model);
    if (!half_r) return half_r.error();
    const Trace& ref = ref_r.value();
    const Errors self = compare(half_r.value(), ref, model);
    refs.push_back({{"level", level}, {"integrator", "rk4"}, {"substeps", opt.reference_substeps},
                    {"self_error_node_rms_cell", self.node_rms}, {"self_error_force_rms_N", self.force_rms_N},
                    {"cell_m", ref.cell_m}});
    for (IntegratorKind kind : kinds)
      for (int sub : opt.substeps)
        for (int it : (uses_iterations(kind) ? opt.iterations : std::vector<int>{0})) {
          Scene cs = s;
          cs.lattice.integrator = kind;
          cs.lattice.substeps = sub;
          cs.lattice.iterations = it;
          if (!opt.quiet)
            std::fprintf(stderr, "bench sim: level %d %s substeps %d iterations %d\n", level, integrator_name(kind), sub, it);
          auto run_r = replay(cs, model);
          if (!run_r) return run_r.error();
          const Trace& run = run_r.value();
          Row r;
          r.integrator = integrator_name(kind);
          r.level = level;
          r.substeps = sub;
          r.iterations = it;
          r.frame_ms_p50 = percentile(run.stats.sim_ms, 0.5);
          r.frame_ms_p99 = percentile(run.stats.sim_ms, 0.99);
          r.step_ms_p50 = percentile(run.stats.step_ms, 0.5);
          r.step_ms_p99 = percentile(run.stats.step_ms, 0.99);
          double step_s = 0.0;
          for (double ms : run.stats.step_ms) step_s += ms * 1e-3;
          r.nodes_per_s = step_s > 0 ? static_cast<double>(run.stats.node_frames) / step_s : 0.0;
          r.springs_per_s = step_s > 0 ? static_cast<double>(run.stats.spring_frames) / step_s : 0.0;
          r.err = compare(run, ref, model);
          r.max_strain = run.max_strain;
          r.max_substeps_taken = run.stats.max_substeps;
          // stable: never reset, and its energy never off the reference's by more than the reference's peak
          r.stable = run.stats.nan_events == 0 && run.stats.divergence_events == 0 && std::isfinite(r.err.node_rms) &&
                     r.max_strain < kDivergedStrain && r.err.energy_drift < 1.0;
          rows.push_back(r);
        }
  }

  // the table
  std::vector<std::size_t> front;
  std::vector<std::vector<std::size_t>> fronts;
  for (int level : levels) {
    fronts.push_back(pareto(rows, level));
    front.insert(front.end(), fronts.back().begin(), fronts.back().end());
  }
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-17s %3s %4s %4s | %7s %7s %7s %7s | %9s %9s %9s | %9s %8s %7s %6s\n", "integrator",
                "lvl", "sub", "iter", "ms p50", "ms p99", "step50", "step99", "node rms", "node max", "vert rms", "force N",
                "E drift", "strain", "stable");
  out += line;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    const bool on_front = std::find(front.begin(), front.end(), i) != front.end();
    std::snprintf(line, sizeof line,
                  "%-17s %3d %4s %4s | %7.3f %7.3f %7.3f %7.3f | %9.2e %9.2e %9.2e | %9.2e %8.2e %7.3f %6s%s\n",
                  r.integrator.c_str(), r.level, r.substeps ? std::to_string(r.substeps).c_str() : "auto",
                  r.iterations ? std::to_string(r.iterations).c_str() : "-", r.frame_ms_p50, r.frame_ms_p99, r.step_ms_p50,
                  r.step_ms_p99,
                  r.err.node_rms, r.err.node_max, r.err.vertex_rms, r.err.force_rms_N, r.err.energy_drift, r.max_strain,
                  r.stable ? "yes" : "NO", on_front ? "  *" : "");
    out += line;
  }
  out += "errors against the rk4 reference, in cells (node, vertex) and N (device force); * = Pareto front of its level\n";
  for (const auto& ref : refs) {
    std::snprintf(line, sizeof line, "reference level %d: rk4 x%d substeps, self-error (vs half as many) %.2e cell, %.2e N\n",
                  ref["level"].get<int>(), ref["substeps"].get<int>(), ref["self_error_node_rms_cell"].get<double>(),
                  ref["self_error_force_rms_N"].get<double>());
    out += line;
  }

  if (!opt.json_path.empty()) {
    nlohmann::json j;
    j["scene"] = scene_path;
    j["duration_s"] = base.duration_s;
    j["references"] = refs;
    j["rows"] = nlohmann::json::array();
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      j["rows"].push_back({{"integrator", r.integrator}, {"level", r.level}, {"substeps", r.substeps},
                           {"iterations", r.iterations}, {"max_substeps_taken", r.max_substeps_taken},
                           {"frame_ms", {{"p50", r.frame_ms_p50}, {"p99", r.frame_ms_p99}}},
                           {"step_ms", {{"p50", r.step_ms_p50}, {"p99", r.step_ms_p99}}},
                           {"nodes_per_s", r.nodes_per_s}, {"springs_per_s", r.springs_per_s},
                           {"node_error_cell", {{"rms", r.err.node_rms}, {"max", r.err.node_max}}},
                           {"vertex_error_cell_rms", r.err.vertex_rms}, {"force_error_N_rms", r.err.force_rms_N},
                           {"energy_drift", r.err.energy_drift}, {"max_strain", r.max_strain}, {"stable", r.stable},
                           {"pareto", std::find(front.begin(), front.end(), i) != front.end()}});
    }
    if (auto st = write_file_atomic(opt.json_path, j.dump(2) + "\n", "bench json"); !st) return st.error();
  }
  if (plot != nullptr && !opt.plot_path.empty()) {
    PlotSpec& p = *plot;
    p = PlotSpec{};
    p.title = "speed against error: " + base.name;
    p.what = "palpate bench sim " + scene_path + ": stable rows per integrator, then the Pareto front per level";
    p.x_label = "sim ms per frame (median)";
    p.y_label = "node error RMS (cells, against RK4)";
    p.x_column = "frame_ms_p50";
    p.key_outside = true;  // seven entries: beside the graph, never over a point
    p.y_column = "node_error_rms_cell";
    static const std::map<std::string, std::pair<const char*, int>> kLook{
        {"explicit_euler", {"#c82828", 7}}, {"symplectic_euler", {"#1e6ec8", 5}}, {"implicit_euler", {"#28963c", 9}},
        {"local_global", {"#e68c14", 13}}, {"rk4", {"#823caa", 11}}};
    auto add_row = [](PlotSeries* s, const Row& r) {
      s->x.push_back(r.frame_ms_p50);
      s->y.push_back(std::max(r.err.node_rms, 1e-12));
      s->extra[0].values.push_back(r.level);
      s->extra[1].values.push_back(r.substeps);
      s->extra[2].values.push_back(r.iterations);
    };
    auto new_series = [](const std::string& label, const char* colour) {
      PlotSeries s;
      s.label = label;
      s.colour = colour;
      s.extra = {{"level", {}}, {"substeps", {}}, {"iterations", {}}};
      return s;
    };
    for (const auto& [name, look] : kLook) {
      PlotSeries s = new_series(name, look.first);
      s.point_type = look.second;
      for (const Row& r : rows)
        if (r.integrator == name && r.stable) add_row(&s, r);
      if (!s.x.empty()) p.series.push_back(s);
    }
    // one Pareto line per level, darker for finer levels
    for (std::size_t l = 0; l < levels.size(); ++l) {
      const int grey = levels.size() > 1 ? static_cast<int>(150 - 150 * l / (levels.size() - 1)) : 0;
      char colour[8];
      std::snprintf(colour, sizeof colour, "#%02x%02x%02x", grey, grey, grey);
      PlotSeries f = new_series("Pareto front, level " + std::to_string(levels[l]), colour);
      f.style = PlotStyle::kLines;
      for (std::size_t i : fronts[l]) add_row(&f, rows[i]);
      p.series.push_back(f);
    }
  }
  return out;
}

}  // namespace palpate
