#include "tools/bench_material.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "sim/integrator.h"
#include "sim/reference_cases.h"

namespace palpate {
namespace {

struct FrameCost {
  double ms = 0.0;    // mean wall time of one 1/60 s frame
  int substeps = 0;   // substeps of the last frame
};

// Times frames of the case's lattice: nodes with a held DOF fixed, its load applied, from the displaced state.
FrameCost time_frames(const ReferenceCase& c, IntegratorKind kind, int frames) {
  Lattice lat = c.lattice;
  for (std::size_t i = 0; i < lat.num_nodes(); ++i)
    lat.fixed[i] = c.held_dof[3 * i] || c.held_dof[3 * i + 1] || c.held_dof[3 * i + 2];
  lat.touch();
  StepOptions o;
  o.kind = kind;
  o.max_substeps = 100000;
  IntegratorWorkspace ws;
  FrameCost cost;
  for (int f = 0; f < 2; ++f) step_lattice(&lat, o, 1.0 / 60.0, c.f_ext_N, &ws);
  const auto t0 = std::chrono::steady_clock::now();
  for (int f = 0; f < frames; ++f) cost.substeps = step_lattice(&lat, o, 1.0 / 60.0, c.f_ext_N, &ws).substeps;
  cost.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / frames;
  return cost;
}

}  // namespace

Result<std::string> run_bench_material(const BenchMaterialOptions& o) {
  MaterialSpec m;
  m.enabled = true;
  m.young_modulus_Pa = o.young_modulus_Pa;
  m.poisson_ratio = 0.25;
  m.density_kg_per_m3 = o.density_kg_per_m3;
  m.stiffness_damping_s = o.stiffness_damping_s;
  std::ostringstream t;
  char line[256];
  std::snprintf(line, sizeof line, "E %.3g Pa, nu 0.25, rho %.4g kg/m^3, beta %.3g s; frame = 1/60 s, mean of %d after 2 warm-up\n",
                o.young_modulus_Pa, o.density_kg_per_m3, o.stiffness_damping_s, o.timed_frames);
  t << line;
  t << "reference    level  cells/side  nodes  springs  model          closed form    rel error   symplectic ms (substeps)  local_global ms\n";
  nlohmann::json rows = nlohmann::json::array();
  auto row = [&](const char* name, int level, const ReferenceCase& c, const ReferenceCheck& r, const char* unit) {
    const FrameCost se = time_frames(c, IntegratorKind::kSymplecticEuler, o.timed_frames);
    const FrameCost lg = time_frames(c, IntegratorKind::kLocalGlobal, o.timed_frames);
    const int cells = c.lattice.cells_per_axis;
    std::snprintf(line, sizeof line, "%-12s %5d  %10d  %5zu  %7zu  %.5e %s  %.5e %s  %+9.2e   %9.2f (%4d)           %8.2f\n", name,
                  level, std::string(name) == "cantilever" ? cells / 8 : cells, r.nodes, r.springs, r.model, unit,
                  r.closed_form, unit, r.rel_error, se.ms, se.substeps, lg.ms);
    t << line;
    rows.push_back({{"reference", name}, {"level", level}, {"nodes", r.nodes}, {"springs", r.springs},
                    {"model", r.model}, {"closed_form", r.closed_form}, {"unit", unit}, {"rel_error", r.rel_error},
                    {"poisson_effective", r.poisson_effective}, {"newton_steps", r.newton_steps},
                    {"symplectic_euler_ms_per_frame", se.ms}, {"symplectic_euler_substeps", se.substeps},
                    {"local_global_ms_per_frame", lg.ms}});
  };
  for (int level : o.compression_levels) {
    auto c = compression_case(m, level, 1e-6);
    auto r = check_compression(m, level, 1e-6);
    if (!c || !r) return make_error("bench material: compression level ", std::to_string(level), ": ",
                                    (!c ? c.error() : r.error()).message);
    row("compression", level, c.value(), r.value(), "N");
  }
  for (int level : o.hertz_levels) {
    // the indented block is the compression cube's lattice: its frame cost is timed on that case
    auto c = compression_case(m, level, 1e-6);
    auto r = check_hertz(m, level);
    if (!c || !r) return make_error("bench material: hertz level ", std::to_string(level), ": ",
                                    (!c ? c.error() : r.error()).message);
    row("hertz", level, c.value(), r.value(), "N");
  }
  for (int level : o.cantilever_levels) {
    auto c = cantilever_case(m, level);
    auto r = check_cantilever(m, level);
    if (!c || !r) return make_error("bench material: cantilever level ", std::to_string(level), ": ",
                                    (!c ? c.error() : r.error()).message);
    row("cantilever", level, c.value(), r.value(), "m");
  }
  t << "cells/side: compression and hertz (quarter block) cells per side; cantilever cells across the 1 cm section (8x as many along it)\n";
  if (!o.json_path.empty()) {
    nlohmann::json j{{"young_modulus_Pa", o.young_modulus_Pa}, {"poisson_ratio", 0.25},
                     {"density_kg_per_m3", o.density_kg_per_m3}, {"stiffness_damping_s", o.stiffness_damping_s},
                     {"rows", rows}};
    std::ofstream f(o.json_path);
    f << j.dump(2) << "\n";
    if (!f) return make_error("bench material: cannot write '", o.json_path, "'");
  }
  return t.str();
}

}  // namespace palpate
