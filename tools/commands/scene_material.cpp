#include "tools/commands/scene_material.h"

#include <cmath>
#include <cstdio>

namespace palpate {
namespace {

// Rayleigh beta: the tissue scene's, enough to settle a press within a few frames at these stiffnesses
constexpr double kStiffnessDamping_s = 5e-3;

bool within(double x, double lo, double hi) { return std::isfinite(x) && x >= lo && x <= hi; }

}  // namespace

Status check_scene_material(double young_modulus_Pa, double poisson_ratio, double density_kg_per_m3) {
  if (young_modulus_Pa == 0.0) return Ok{};
  char buf[160];
  if (!within(young_modulus_Pa, 1.0, 1e9)) {
    std::snprintf(buf, sizeof buf, "--young-modulus %g: not a number in [1, 1e9] Pa", young_modulus_Pa);
    return make_error(buf);
  }
  if (!within(poisson_ratio, 0.0, 0.49)) {
    std::snprintf(buf, sizeof buf, "--poisson %g: not a number in [0, 0.49]", poisson_ratio);
    return make_error(buf);
  }
  if (!within(density_kg_per_m3, 1.0, 1e5)) {
    std::snprintf(buf, sizeof buf, "--density %g: not a number in [1, 1e5] kg/m^3", density_kg_per_m3);
    return make_error(buf);
  }
  return Ok{};
}

SceneMaterial scene_material(InteractionMode mode, double young_modulus_Pa, double poisson_ratio,
                             double density_kg_per_m3) {
  SceneMaterial m;
  const char* model = mode == InteractionMode::kTouch ? "volumetric"
                      : mode == InteractionMode::kPull ? "neo_hookean"
                                                       : "springs";
  const char* why = mode == InteractionMode::kTouch ? "the volume term: nu as asked"
                    : mode == InteractionMode::kPull ? "large strain, nu as asked"
                                                     : "cut mode takes the springs alone: nu 0.25 in the lattice";
  // local/global prefactors springs only; the cell terms need implicit Euler
  m.integrator = mode == InteractionMode::kCut ? "local_global" : "implicit_euler";
  m.json = {{"young_modulus_Pa", young_modulus_Pa},
            {"poisson_ratio", poisson_ratio},
            {"density_kg_per_m3", density_kg_per_m3},
            {"stiffness_damping_s", kStiffnessDamping_s},
            {"model", model}};
  char buf[240];
  std::snprintf(buf, sizeof buf, "material E %g Pa, nu %g, %g kg/m^3: model %s (%s), %s", young_modulus_Pa,
                poisson_ratio, density_kg_per_m3, model, why, m.integrator.c_str());
  m.note = buf;
  return m;
}

}  // namespace palpate
