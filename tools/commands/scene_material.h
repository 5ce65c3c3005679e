#pragma once
/// `palpate scene --young-modulus E [--poisson NU] [--density RHO]`: a generated scene's material in physical units,
/// its model chosen by what the mode needs — a touch the volume term (`volumetric`: any nu), a pull large strain
/// (`neo_hookean`), a cut the springs alone (cut mode takes no cell terms: nu 0.25 in the lattice, said so) — and
/// the integrator that carries that model.

#include <string>

#include <nlohmann/json.hpp>

#include "core/result.h"
#include "core/scene_enums.h"

namespace palpate {

/// A generated scene's "material" block, its lattice.integrator and one line saying what was chosen. Plain data.
struct SceneMaterial {
  nlohmann::ordered_json json;  ///< the scene's "material" object
  std::string integrator;       ///< lattice.integrator
  std::string note;             ///< "material E 20000 Pa, nu 0.45, 1050 kg/m^3: model volumetric (...), implicit_euler"
};

/// Errors name the option out of range: --young-modulus in [1, 1e9] Pa, --poisson in [0, 0.49], --density in
/// [1, 1e5] kg/m^3 (young_modulus_Pa 0: no material, nothing checked).
Status check_scene_material(double young_modulus_Pa, double poisson_ratio, double density_kg_per_m3);

/// The block for `mode` (after check_scene_material).
SceneMaterial scene_material(InteractionMode mode, double young_modulus_Pa, double poisson_ratio,
                             double density_kg_per_m3);

}  // namespace palpate
