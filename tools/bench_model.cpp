#include "tools/bench_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "sim/material.h"
#include "sim/reference_cases.h"
#include "tools/plot.h"
#include "tools/session/model.h"
#include "tools/session/tool_hold.h"

namespace palpate {
namespace {

constexpr double kHertzRadius_m = 0.1;
constexpr double kHertzDepth_m = 2.5e-4;
constexpr double kBlockSide_m = 0.08, kBlockDepth_m = 0.04;
constexpr double kCoupling_N_per_m = 300.0;

double hertz_force_N(double young_modulus_Pa, double depth_m) {
  const double e_star = young_modulus_Pa / (1.0 - kLatticePoissonRatio * kLatticePoissonRatio);
  return 4.0 / 3.0 * e_star * std::sqrt(kHertzRadius_m) * std::pow(std::max(depth_m, 0.0), 1.5);
}

// One row of the table: a reference at a level.
struct Row {
  std::string reference;
  int level = 0;
  std::size_t nodes = 0, springs = 0;
  double model = 0.0, closed_form = 0.0, rel_error = 0.0;
  const char* unit = "";
  double ms_per_frame = 0.0;
  int64_t frames = 0;
};

}  // namespace

Result<HertzToolCheck> check_hertz_tool(const MaterialSpec& material, int level, IntegratorKind integrator) {
  // the block's top lies just below a cell plane, so no empty cell above it joins the lattice
  const double top = 0.5 * kBlockDepth_m * (1.0 - 1e-3);
  // the device held where the sphere, pushed back by the Hertz force through the coupling, sits about d deep
  const double device_z = top + kHertzRadius_m - kHertzDepth_m -
                          hertz_force_N(material.young_modulus_Pa, kHertzDepth_m) / kCoupling_N_per_m;
  const int cells = 1 << (level - 1);
  nlohmann::json j = {
      {"name", "hertz"},
      {"mesh", {{"box_m", {kBlockSide_m, kBlockSide_m, 2.0 * top}}, {"box_subdivisions", 32}, {"size_m", kBlockSide_m}}},
      {"grid", {{"levels", std::max(level, 4)}}},
      {"lattice", {{"level", level}, {"radius_cells", cells}, {"fix_floor", true}, {"integrator", integrator_name(integrator)}}},
      {"material", {{"young_modulus_Pa", material.young_modulus_Pa}, {"poisson_ratio", material.poisson_ratio},
                    {"density_kg_per_m3", material.density_kg_per_m3},
                    {"stiffness_damping_s", material.stiffness_damping_s}}},
      {"device", {{"max_force_N", 100.0}, {"coupling_N_per_m", kCoupling_N_per_m}, {"coupling_damping_Ns_per_m", 0.0},
                  {"tool_radius_m", kHertzRadius_m}, {"tool_shape", "sphere"}, {"workspace_half_m", 1.0},
                  {"max_stiffness_N_per_m", kCoupling_N_per_m}}},
      {"interaction", {{"mode", "touch"}}},
      {"trajectory", {{{"t_s", 0.0}, {"pos_m", {0.0, 0.0, device_z}}}}},
  };
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
    return make_error("hertz level ", std::to_string(level), ": not at rest after ", std::to_string(h.frames), " frames");
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
  c.closed_form_N = hertz_force_N(material.young_modulus_Pa, c.depth_m);
  c.rel_error = c.force_N / c.closed_form_N - 1.0;
  c.nodes = h.nodes;
  c.springs = h.springs;
  c.force_nodes = h.force_nodes;
  c.frames = h.frames;
  c.ms_per_frame_p50 = h.sim_ms_p50;
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
    if (name != "compression" && name != "cantilever" && name != "hertz")
      return make_error("bench model: reference '", name, "' is not one of: compression, cantilever, hertz");
  for (int level : o.levels) {
    if (!wanted("compression")) break;
    auto r = check_compression(m, level, 1e-4, so);
    if (!r) return make_error("bench model: compression level ", std::to_string(level), ": ", r.error().message);
    rows.push_back({"compression", level, r.value().nodes, r.value().springs, r.value().model, r.value().closed_form,
                    r.value().rel_error, "m", r.value().settle.ms_per_frame_p50, r.value().settle.frames});
  }
  for (int level : o.levels) {
    if (!wanted("cantilever")) break;
    if (level < 4) continue;  // the beam needs one cell across
    auto r = check_cantilever(m, level, so);
    if (!r) return make_error("bench model: cantilever level ", std::to_string(level), ": ", r.error().message);
    rows.push_back({"cantilever", level, r.value().nodes, r.value().springs, r.value().model, r.value().closed_form,
                    r.value().rel_error, "m", r.value().settle.ms_per_frame_p50, r.value().settle.frames});
  }
  for (int level : o.levels) {
    if (!wanted("hertz")) break;
    auto r = check_hertz_tool(m, level, o.integrator);
    if (!r) return make_error("bench model: hertz level ", std::to_string(level), ": ", r.error().message);
    rows.push_back({"hertz", level, r.value().nodes, r.value().springs, r.value().force_N, r.value().closed_form_N,
                    r.value().rel_error, "N", r.value().ms_per_frame_p50, r.value().frames});
  }
  std::ostringstream t;
  char line[320];
  std::snprintf(line, sizeof line,
                "E %.3g Pa, nu 0.25, rho %.4g kg/m^3, beta %.3g s; %s, 1/60 s frames until at rest\n", o.young_modulus_Pa,
                o.density_kg_per_m3, o.stiffness_damping_s, integrator_name(o.integrator));
  t << line;
  t << "reference    level   nodes  springs  model          closed form    force error  CPU ms/frame  frames to rest\n";
  nlohmann::json js = nlohmann::json::array();
  for (const Row& r : rows) {
    std::snprintf(line, sizeof line, "%-12s %5d  %6zu  %7zu  %.5e %s  %.5e %s  %+10.2e  %12.2f  %6lld\n", r.reference.c_str(),
                  r.level, r.nodes, r.springs, r.model, r.unit, r.closed_form, r.unit, r.rel_error, r.ms_per_frame,
                  static_cast<long long>(r.frames));
    t << line;
    js.push_back({{"reference", r.reference}, {"level", r.level}, {"nodes", r.nodes}, {"springs", r.springs},
                  {"model", r.model}, {"closed_form", r.closed_form}, {"unit", r.unit}, {"force_error", r.rel_error},
                  {"cpu_ms_per_frame_p50", r.ms_per_frame}, {"frames_to_rest", r.frames}});
  }
  t << "model / closed form: compression shortening, cantilever tip deflection (m), hertz force at the drop of the surface under the sphere (N);\n"
       "force error: the force the lattice needs for the closed form's displacement over the closed form's, minus 1\n";
  if (!o.json_path.empty()) {
    nlohmann::json j{{"young_modulus_Pa", o.young_modulus_Pa}, {"poisson_ratio", 0.25},
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
        if (r.reference == ref) {
          s.x.push_back(r.ms_per_frame);
          s.y.push_back(std::abs(r.rel_error));
          level.values.push_back(r.level);
        }
      s.extra.push_back(level);
      if (!s.x.empty()) p.series.push_back(s);
    }
    *plot = p;
  }
  return t.str();
}

}  // namespace palpate
