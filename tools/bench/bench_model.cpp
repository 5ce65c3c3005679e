#include "tools/bench/bench_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "sim/solvers/frame_budget.h"
#include "sim/reference/hertz_reference.h"
#include "sim/material/material.h"
#include "sim/reference/pull_reference.h"
#include "sim/reference/reference_cases.h"
#include "sim/reference/richardson.h"
#include "tools/bench/bench_press.h"
#include "tools/bench/plot.h"
#include "runtime/session/model.h"
#include "runtime/session/tool_hold.h"

namespace palpate {
namespace {

constexpr double kHertzRadius_m = 0.1;
constexpr double kHertzDepth_m = 2.5e-4;
constexpr double kBlockSide_m = 0.08, kBlockDepth_m = 0.04;
constexpr double kCoupling_N_per_m = 300.0;

// The depths of the solved Hertz rows: the tool check's, and four times it (contact radius 5 and 10 mm).
constexpr double kSolvedDepths_m[] = {2.5e-4, 1e-3};

// One row of the table: a reference at a level.
struct Row {
  std::string reference;
  double nu = kLatticePoissonRatio;   // the lattice's Poisson ratio
  MaterialModel model_kind = MaterialModel::kSprings;
  double lateral = NAN;               // compression: lateral over axial strain (closed form: nu)
  double order = NAN;                 // pull: the observed order of convergence of the Richardson extrapolation
  int level = 0;
  std::size_t nodes = 0, springs = 0;
  double model = 0.0, closed_form = 0.0, rel_error = 0.0;
  const char* unit = "";
  double ms_per_frame = 0.0;
  double step_ms = NAN, cg_iterations = NAN;  // hertz: the step alone (CPU ms per frame) and its CG iterations
  int64_t frames = 0;
  int refine_level = 0;               // hertz refined near the tool to this level (0: uniform)
};

// Hertz on a lattice refined near the tool, beside the uniform lattices at its coarse and fine levels.
struct AdaptiveRow {
  Row coarse, adaptive, fine;
};

}  // namespace

Result<HertzToolCheck> check_hertz_tool(const MaterialSpec& material, int level, IntegratorKind integrator,
                                        const RefineSpec& refine, bool solved_contact) {
  // the block's top lies just below a cell plane, so no empty cell above it joins the lattice
  const double top = 0.5 * kBlockDepth_m * (1.0 - 1e-3);
  // the device held where the sphere, pushed back by the Hertz force through the coupling, sits about d deep
  const double nu = represented_poisson(material);
  const double device_z = top + kHertzRadius_m - kHertzDepth_m -
                          hertz_force_N(material.young_modulus_Pa, nu, kHertzRadius_m, kHertzDepth_m) / kCoupling_N_per_m;
  const int cells = 1 << (level - 1);
  nlohmann::json j = {
      {"name", "hertz"},
      {"mesh", {{"box_m", {kBlockSide_m, kBlockSide_m, 2.0 * top}}, {"box_subdivisions", 32}, {"size_m", kBlockSide_m}}},
      {"grid", {{"levels", std::max({level, 4, refine.level})}}},
      {"lattice", {{"level", level}, {"radius_cells", cells}, {"fix_floor", true}, {"integrator", integrator_name(integrator)}}},
      {"material", {{"young_modulus_Pa", material.young_modulus_Pa}, {"poisson_ratio", material.poisson_ratio},
                    {"density_kg_per_m3", material.density_kg_per_m3},
                    {"stiffness_damping_s", material.stiffness_damping_s}, {"model", name_of(material.model)}}},
      {"device", {{"max_force_N", 100.0}, {"coupling_N_per_m", kCoupling_N_per_m}, {"coupling_damping_Ns_per_m", 0.0},
                  {"tool_radius_m", kHertzRadius_m}, {"tool_shape", "sphere"}, {"workspace_half_m", 1.0},
                  {"max_stiffness_N_per_m", kCoupling_N_per_m}, {"contact", solved_contact ? "solved" : "prescribed"}}},
      {"interaction", {{"mode", "touch"}}},
      {"trajectory", {{{"t_s", 0.0}, {"pos_m", {0.0, 0.0, device_z}}}}},
  };
  if (refine.level > 0) j["lattice"]["refine"] = {{"level", refine.level}, {"radius_m", refine.radius_m}};
  auto scene = parse_scene(j.dump(), "hertz (bench model)");
  if (!scene) return scene.error();
  auto model = load_model(scene.value());
  if (!model) return model.error();
  ToolHoldOptions ho;
  ho.device_pos_m = Vec3(0.0, 0.0, device_z);
  auto held = hold_tool(scene.value(), model.value(), ho);
  if (!held) return held.error();
  const ToolHoldResult& h = held.value();
  if (!h.at_rest)
    return make_error("hertz level ", std::to_string(level), ": not at rest after ", std::to_string(h.frames), " frames (",
                      std::to_string(h.region_moves), " region moves)");
  HertzToolCheck c;
  c.force_N = h.force_N.z();
  c.sphere_depth_m = top - (h.proxy_m.z() - kHertzRadius_m);
  // the surface under the centre: the top-face vertex nearest the sphere's axis
  const TriMesh& rest = model.value().rest;
  std::size_t under = 0;
  double best = INFINITY;
  for (std::size_t v = 0; v < rest.vertices_m.size(); ++v) {
    const Vec3& p = rest.vertices_m[v];
    const double d = std::hypot(p.x() - h.proxy_m.x(), p.y() - h.proxy_m.y()) + std::abs(p.z() - top);
    if (d < best) best = d, under = v;
  }
  c.depth_m = rest.vertices_m[under].z() - h.vertices_m[under].z();
  c.closed_form_N = hertz_force_N(material.young_modulus_Pa, nu, kHertzRadius_m, c.depth_m);
  c.rel_error = c.force_N / c.closed_form_N - 1.0;
  c.nodes = h.nodes;
  c.springs = h.springs;
  c.force_nodes = h.force_nodes;
  c.solved_frames = h.solved_frames;
  c.frames = h.frames;
  c.region_moves = h.region_moves;
  c.ms_per_frame_p50 = h.sim_ms_p50;
  c.step_ms_p50 = h.step_ms_p50;
  c.cg_iterations_p50 = h.cg_iterations_p50;
  return c;
}

Result<std::string> run_bench_model(const BenchModelOptions& o, PlotSpec* plot) {
  if (!o.json_path.empty())
    if (auto st = check_output_target(o.json_path, "bench model output"); !st) return st.error();
  if (!o.plot_path.empty())
    if (auto st = check_plot_targets(o.plot_path); !st) return st.error();
  MaterialSpec m;
  m.enabled = true;
  m.young_modulus_Pa = o.young_modulus_Pa;
  m.poisson_ratio = 0.25;
  m.density_kg_per_m3 = o.density_kg_per_m3;
  m.stiffness_damping_s = o.stiffness_damping_s;
  SettleOptions so;
  so.step.kind = o.integrator;
  std::vector<Row> rows;
  auto wanted = [&](const char* name) { return std::find(o.references.begin(), o.references.end(), name) != o.references.end(); };
  for (const std::string& name : o.references)
    if (name != "none" && name != "compression" && name != "cantilever" && name != "hertz" && name != "hertz-solved" && name != "pull")
      return make_error("bench model: reference '", name,
                        "' is not one of: compression, cantilever, hertz, hertz-solved, pull, none");
  for (std::size_t k = 1; k < o.pull_levels.size(); ++k)
    if (o.pull_levels.size() != 3 || o.pull_levels[k] != o.pull_levels[k - 1] + 1)
      return make_error("bench model: --pull-levels needs three consecutive levels (e.g. 3,4,5)");
  // one reference at one level for material mat: its row, or an error naming them
  const auto started = std::chrono::steady_clock::now();
  auto seconds_since = [](std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  double adaptive_wall_s = 0.0;  // wall time of the adaptive rows (said on stderr beside the whole run's)
  auto run = [&](const std::string& ref, const MaterialSpec& mat, int level, const RefineSpec& refine = {}) -> Result<Row> {
    // a run to rest takes seconds to a minute: say which is under way (stderr; the table goes to stdout)
    std::fprintf(stderr, "bench model: %s, level %d%s, nu %.2f ...\n", ref.c_str(), level,
                 refine.level > 0 ? (" refined to " + std::to_string(refine.level)).c_str() : "", represented_poisson(mat));
    Row row;
    row.reference = ref;
    row.level = level;
    row.nu = represented_poisson(mat);
    row.model_kind = mat.model;
    row.refine_level = refine.level;
    if (ref == "hertz") {
      auto r = check_hertz_tool(mat, level, o.integrator, refine, o.solved_contact);
      if (!r) return make_error("bench model: hertz level ", std::to_string(level), ": ", r.error().message);
      const HertzToolCheck& h = r.value();
      row.nodes = h.nodes, row.springs = h.springs, row.model = h.force_N, row.closed_form = h.closed_form_N;
      row.rel_error = h.rel_error, row.unit = "N", row.ms_per_frame = h.ms_per_frame_p50, row.frames = h.frames;
      row.step_ms = h.step_ms_p50, row.cg_iterations = h.cg_iterations_p50;
      return row;
    }
    auto r = ref == "compression" ? check_compression(mat, level, 1e-4, so) : check_cantilever(mat, level, so);
    if (!r) return make_error("bench model: ", ref, " level ", std::to_string(level), ": ", r.error().message);
    const ReferenceCheck& c = r.value();
    row.nodes = c.nodes, row.springs = c.springs, row.model = c.model, row.closed_form = c.closed_form;
    row.rel_error = c.rel_error, row.unit = "m", row.ms_per_frame = c.settle.ms_per_frame_p50, row.frames = c.settle.frames;
    if (ref == "compression") row.lateral = c.poisson_effective;
    return row;
  };
  // Hertz with the contact solved under the sphere (sim/reference/hertz_reference.h): prescribed depth, solved force; one row
  // per depth, CPU ms of the whole static solve in the CPU column and its Newton steps in the last; graded from
  // `coarse` (> 0) to `level` near the contact (printed coarse>level)
  auto run_solved = [&](const MaterialSpec& mat, int level, int coarse = 0) -> Status {
    for (double depth : kSolvedDepths_m) {
      std::fprintf(stderr, "bench model: hertz solved, level %d%s, depth %.2f mm, nu %.2f ...\n", level,
                   coarse > 0 ? (" graded from " + std::to_string(coarse)).c_str() : "", 1e3 * depth,
                   represented_poisson(mat));
      ThreadCpuClock cpu;
      const double c0 = cpu.now_ms();
      HertzSolvedOptions ho;
      ho.iterative = coarse == 0 && level >= 7;
      ho.coarse_level = coarse;
      ho.zone_over_contact = o.solved_zone;
      ho.block_scale = o.solved_block_scale;
      auto r = solve_hertz_block(mat, level, kHertzRadius_m, depth, ho);
      if (!r) return make_error("bench model: ", r.error().message);
      Row row;
      row.reference = depth < 5e-4 ? "hertz-s.25mm" : "hertz-s 1mm";
      row.level = coarse > 0 ? coarse : level;
      row.refine_level = coarse > 0 ? level : 0;
      row.nu = represented_poisson(mat);
      row.model_kind = mat.model;
      row.nodes = r.value().nodes, row.springs = r.value().springs, row.model = r.value().force_N;
      row.closed_form = r.value().closed_form_N, row.rel_error = r.value().rel_error, row.unit = "N";
      row.ms_per_frame = cpu.now_ms() - c0, row.frames = r.value().iterations;
      std::fprintf(stderr, "bench model: ... %+.2f %% of Hertz, %zu nodes, %.2f s CPU\n", 100.0 * row.rel_error, row.nodes,
                   1e-3 * row.ms_per_frame);
      rows.push_back(row);
    }
    return Ok{};
  };
  if (wanted("hertz-solved"))
    for (int level : o.levels)
      if (level >= 3)
        if (auto st = run_solved(m, level); !st) return st.error();
  if (wanted("hertz-solved"))
    for (int coarse : o.solved_adaptive_levels)
      for (int fine : o.solved_fine_levels)
        if (coarse >= 3 && fine > coarse)
          if (auto st = run_solved(m, fine, coarse); !st) return st.error();
  for (const char* ref : {"compression", "cantilever", "hertz"}) {
    if (!wanted(ref)) continue;
    for (int level : o.levels) {
      if (std::string(ref) == "cantilever" && level < 4) continue;  // the beam needs one cell across
      if (std::string(ref) == "compression" && level > o.compression_max_level) continue;
      auto row = run(ref, m, level);
      if (!row) return row.error();
      rows.push_back(row.value());
    }
  }
  // adaptive vs uniform: Hertz with the lattice refined near the tool, beside the uniform coarse and fine levels
  // (those of the sweep above when it ran them, else run here and added to it): springs, then poisson_model at each
  // adaptive nu
  std::vector<AdaptiveRow> adaptive;
  std::vector<std::pair<MaterialSpec, int>> adaptive_runs;
  for (std::size_t k = 0; k <= o.adaptive_poisson_ratios.size(); ++k) {
    MaterialSpec mat = m;
    if (k > 0) mat.model = o.poisson_model, mat.poisson_ratio = o.adaptive_poisson_ratios[k - 1];
    for (int coarse : o.adaptive_levels) adaptive_runs.emplace_back(mat, coarse);
  }
  if (wanted("hertz"))
    for (const auto& [mat_spec, coarse] : adaptive_runs) {
      const MaterialSpec& mat = mat_spec;  // a reference the lambda below can capture
      if (coarse < 2 || coarse >= o.adaptive_fine_level) continue;
      auto uniform = [&](int level) -> Result<Row> {
        for (const Row& r : rows)
          if (r.reference == "hertz" && r.model_kind == mat.model && r.nu == represented_poisson(mat) && r.level == level &&
              r.refine_level == 0)
            return r;
        auto row = run("hertz", mat, level);
        if (row) rows.push_back(row.value());
        return row;
      };
      auto c = uniform(coarse);
      if (!c) return c.error();
      RefineSpec refine;
      refine.level = o.adaptive_fine_level;
      refine.radius_m = o.adaptive_radius_m;
      const auto a0 = std::chrono::steady_clock::now();
      auto a = run("hertz", mat, coarse, refine);
      adaptive_wall_s += seconds_since(a0);
      if (!a) return a.error();
      Row fine;  // not run: zeros, printed as such
      if (o.adaptive_uniform_fine) {
        auto f = uniform(o.adaptive_fine_level);
        if (!f) return f.error();
        fine = f.value();
      }
      a.value().reference = "hertz adapt";
      rows.push_back(a.value());
      adaptive.push_back({c.value(), a.value(), fine});
    }
  // the volumetric model at each nu: compression at level 4 (uniform strain: any level), the others at poisson_level
  for (double nu : o.poisson_ratios) {
    MaterialSpec mv = m;
    mv.model = o.poisson_model;
    mv.poisson_ratio = nu;
    for (const char* ref : {"compression", "cantilever", "hertz"}) {
      if (!wanted(ref)) continue;
      auto row = run(ref, mv, std::string(ref) == "compression" ? 4 : o.poisson_level);
      if (!row) return make_error(row.error().message, " (material.model ", name_of(o.poisson_model), ", nu ", std::to_string(nu), ")");
      rows.push_back(row.value());
    }
    if (wanted("hertz-solved"))
      if (auto st = run_solved(mv, o.poisson_level); !st)
        return make_error(st.error().message, " (material.model ", name_of(o.poisson_model), ", nu ", std::to_string(nu), ")");
  }
  // large strain: 30 % compression of the Neo-Hookean model against the Neo-Hookean closed form, per nu (uniform
  // strain: one level does); the 40 mm pull against the Richardson extrapolation of its three levels
  for (double nu : o.large_strain_poisson_ratios) {
    MaterialSpec mn = m;
    mn.model = MaterialModel::kNeoHookean;
    mn.poisson_ratio = nu;
    if (wanted("compression")) {
      auto r = check_large_compression(mn, 3, 0.3, so);
      if (!r) return make_error("bench model: large compression nu ", std::to_string(nu), ": ", r.error().message);
      const ReferenceCheck& c = r.value();
      Row row;
      row.reference = "compress 30%";
      row.nu = nu;
      row.model_kind = MaterialModel::kNeoHookean;
      row.level = 3;
      row.nodes = c.nodes, row.springs = c.springs, row.model = c.model, row.closed_form = c.closed_form;
      row.rel_error = c.rel_error, row.unit = "N", row.ms_per_frame = c.settle.ms_per_frame_p50, row.frames = c.settle.frames;
      row.lateral = c.poisson_effective;
      rows.push_back(row);
    }
    if (wanted("pull") && !o.pull_levels.empty()) {
      std::vector<Row> pulls;
      for (int level : o.pull_levels) {
        auto r = check_pull(mn, level, PullGeometry{}, so);
        if (!r) return make_error("bench model: pull nu ", std::to_string(nu), ": ", r.error().message);
        Row row;
        row.reference = "pull 40mm";
        row.nu = nu;
        row.model_kind = MaterialModel::kNeoHookean;
        row.level = level;
        row.nodes = r.value().nodes, row.springs = r.value().springs, row.model = r.value().force_N, row.unit = "N";
        row.ms_per_frame = r.value().settle.ms_per_frame_p50, row.frames = r.value().settle.frames;
        pulls.push_back(row);
      }
      auto ext = richardson_extrapolate(pulls[0].model, pulls[1].model, pulls[2].model);
      if (!ext) return make_error("bench model: pull nu ", std::to_string(nu), ": ", ext.error().message);
      for (Row& row : pulls) {
        row.closed_form = ext.value().value;
        row.rel_error = row.model / row.closed_form - 1.0;
        row.order = ext.value().order;
        rows.push_back(row);
      }
    }
  }
  std::fprintf(stderr, "bench model: %.0f s wall in all, %.1f s of it the adaptive rows\n", seconds_since(started),
               adaptive_wall_s);
  std::ostringstream t;
  char line[400];
  std::snprintf(line, sizeof line,
                "E %.3g Pa, rho %.4g kg/m^3, beta %.3g s; %s, 1/60 s frames until at rest\n", o.young_modulus_Pa,
                o.density_kg_per_m3, o.stiffness_damping_s, integrator_name(o.integrator));
  t << line;
  t << "reference    material     nu    level   nodes  springs  model          closed form    force error  lateral/axial  CPU ms/frame  frames to rest\n";
  nlohmann::json js = nlohmann::json::array();
  for (const Row& r : rows) {
    char lateral[32] = "-";
    if (std::isfinite(r.lateral)) std::snprintf(lateral, sizeof lateral, "%.4f", r.lateral);
    if (std::isfinite(r.order)) std::snprintf(lateral, sizeof lateral, "order %.2f", r.order);
    char level[16];
    if (r.refine_level > 0) std::snprintf(level, sizeof level, "%d>%d", r.level, r.refine_level);
    else std::snprintf(level, sizeof level, "%d", r.level);
    std::snprintf(line, sizeof line, "%-12s %-11s %5.2f  %5s  %6zu  %7zu  %.5e %s  %.5e %s  %+10.2e  %13s  %12.2f  %6lld\n",
                  r.reference.c_str(), name_of(r.model_kind), r.nu, level, r.nodes, r.springs, r.model, r.unit,
                  r.closed_form, r.unit, r.rel_error, lateral, r.ms_per_frame, static_cast<long long>(r.frames));
    t << line;
    nlohmann::json row = {{"reference", r.reference}, {"material_model", name_of(r.model_kind)}, {"poisson_ratio", r.nu},
                          {"level", r.level}, {"nodes", r.nodes}, {"springs", r.springs}, {"model", r.model},
                          {"closed_form", r.closed_form}, {"unit", r.unit}, {"force_error", r.rel_error},
                          {"cpu_ms_per_frame_p50", r.ms_per_frame}, {"frames_to_rest", r.frames}};
    if (std::isfinite(r.lateral)) row["lateral_over_axial"] = r.lateral;
    if (std::isfinite(r.order)) row["richardson_order"] = r.order;
    if (r.refine_level > 0) row["refine_level"] = r.refine_level;
    if (r.reference == "hertz") row["contact"] = o.solved_contact ? "solved" : "prescribed";
    js.push_back(row);
  }
  t << "model / closed form: compression shortening, cantilever tip deflection (m), hertz force at the drop of the surface under the sphere (N;\n"
       "the sphere's push spread by " << (o.solved_contact ? "the contact solved under it, --contact solved" : "Hertz's pressure, --contact prescribed") << ");\n"
       "force error: the force the lattice needs for the closed form's displacement over the closed form's, minus 1;\n"
       "lateral/axial: compression's lateral over axial strain (closed form: nu); springs: central springs only (nu 0.25),\n"
       "volumetric: springs for the shear modulus plus each cell's volume term (below nu 0.25: the neo_hookean split),\n"
       "neo_hookean: a tenth of mu in springs, the rest each cell's Neo-Hookean term (material.model);\n"
       "compress 30%: the 4 cm cube between frictionless plates moved 30 % together, model = the plates' force against\n"
       "the compressible Neo-Hookean solid's uniaxial stress x face (closed form), lateral column = lateral stretch over\n"
       "the closed form's, minus 1; pull 40mm: the 8 cm cube glued to the floor and to a plate pulled up 40 mm, the\n"
       "plate's force against the Richardson extrapolation of the three levels (not a closed form; order p observed);\n"
       "hertz-s: the contact solved under the sphere (R 10 cm pressed 0.25 or 1 mm into the hertz block; the lattice's\n"
       "surface kept outside it, the force the sum of the reactions), model = solved force against Hertz's at that depth;\n"
       "its CPU column is the whole static solve's CPU ms (one thread), its last column the Newton steps; level C>F:\n"
       "graded from level C far away to F within --solved-zone contact radii of the axis (twice that into the body)\n";
  if (!o.press_scene.empty()) {
    auto press = run_solved_press(o.press_scene, o.press_young_modulus_Pa, o.press_levels);
    if (!press) return make_error("bench model: ", press.error().message);
    std::snprintf(line, sizeof line, "\nsolved press: %s, E %.3g Pa, its tool a rigid sphere held by the coupling and hand "
                  "springs at the trajectory's lowest key\n", o.press_scene.c_str(), o.press_young_modulus_Pa);
    t << line;
    t << "level  radius cells   nodes  samples/edge  force N   depth mm  in contact  Newton steps  penalty give um\n";
    for (const PressRow& p : press.value()) {
      if (!p.failure.empty()) {
        std::snprintf(line, sizeof line, "%5d  %12d  %6zu  %12d  no equilibrium: ", p.level, p.radius_cells, p.nodes,
                      p.samples_per_edge);
        t << line << p.failure << "\n";
        continue;
      }
      std::snprintf(line, sizeof line, "%5d  %12d  %6zu  %12d  %7.4f  %9.3f  %10d  %12d  %15.3f\n", p.level, p.radius_cells,
                    p.nodes, p.samples_per_edge, p.force_N, 1e3 * p.depth_m, p.active, p.iterations, 1e6 * p.max_penetration_m);
      t << line;
    }
  }
  if (!adaptive.empty()) {
    std::snprintf(line, sizeof line,
                  "\nadaptive vs uniform: hertz by the sphere tool, the cells within %.1f mm of the contact refined to "
                  "level %d\n", 1e3 * o.adaptive_radius_m, o.adaptive_fine_level);
    t << line;
    t << "material     nu    coarse level  uniform coarse: nodes  error  CPU ms  step ms  CG it | adaptive: nodes  error  "
         "CPU ms  step ms  CG it  CPU/coarse | uniform fine: nodes  error  CPU ms\n";
    for (const AdaptiveRow& a : adaptive) {
      std::snprintf(line, sizeof line,
                    "%-11s %5.2f  %12d  %21zu  %+.2e  %6.2f  %7.2f  %5.0f | %15zu  %+.2e  %6.2f  %7.2f  %5.0f  %10.2f | %19zu  "
                    "%+.2e  %6.2f\n",
                    name_of(a.adaptive.model_kind), a.adaptive.nu, a.coarse.level, a.coarse.nodes, a.coarse.rel_error,
                    a.coarse.ms_per_frame, a.coarse.step_ms, a.coarse.cg_iterations, a.adaptive.nodes, a.adaptive.rel_error,
                    a.adaptive.ms_per_frame, a.adaptive.step_ms, a.adaptive.cg_iterations, a.adaptive.ms_per_frame / a.coarse.ms_per_frame,
                    a.fine.nodes, a.fine.rel_error, a.fine.ms_per_frame);
      t << line;
    }
  }
  if (!o.json_path.empty()) {
    nlohmann::json j{{"young_modulus_Pa", o.young_modulus_Pa},
                     {"density_kg_per_m3", o.density_kg_per_m3}, {"stiffness_damping_s", o.stiffness_damping_s},
                     {"integrator", integrator_name(o.integrator)}, {"rows", js}};
    if (auto st = write_file_atomic(o.json_path, j.dump(2) + "\n", "bench json"); !st) return st.error();
  }
  if (plot != nullptr && !o.plot_path.empty()) {
    // model error against cost, one line per reference through its levels (log-log)
    PlotSpec p;
    p.title = "model error against cost per lattice level";
    p.x_label = "CPU ms per 1/60 s frame";
    p.y_label = "|force error| against the closed form";
    p.x_column = "cpu_ms_per_frame";
    p.y_column = "abs_force_error";
    char what[160];
    std::snprintf(what, sizeof what, "palpate bench model (E %g Pa, nu 0.25, density %g kg/m^3)", o.young_modulus_Pa,
                  o.density_kg_per_m3);
    p.what = what;
    p.key = "top right";
    const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c"};
    const int points[] = {7, 5, 9};
    int c = 0;
    for (const char* ref : {"compression", "cantilever", "hertz"}) {
      PlotSeries s;
      s.label = ref;
      s.colour = colours[c];
      s.point_type = points[c++];
      s.style = PlotStyle::kLinesPoints;
      PlotColumn level{"level", {}};
      for (const Row& r : rows)
        if (r.reference == ref && r.model_kind == MaterialModel::kSprings) {
          s.x.push_back(r.ms_per_frame);
          s.y.push_back(std::abs(r.rel_error));
          level.values.push_back(r.level);
        }
      s.extra.push_back(level);
      if (!s.x.empty()) p.series.push_back(s);
    }
    // the adaptive lattices: one point per coarse level, beside the uniform hertz line
    PlotSeries ad;
    ad.label = "hertz adaptive";
    ad.colour = "#9467bd";
    ad.point_type = 11;
    ad.style = PlotStyle::kLinesPoints;
    PlotColumn level{"level", {}};
    for (const Row& r : rows)
      if (r.refine_level > 0 && r.model_kind == MaterialModel::kSprings) {
        ad.x.push_back(r.ms_per_frame);
        ad.y.push_back(std::abs(r.rel_error));
        level.values.push_back(r.level);
      }
    ad.extra.push_back(level);
    if (!ad.x.empty()) p.series.push_back(ad);
    *plot = p;
  }
  return t.str();
}

}  // namespace palpate
