#pragma once
/// What a scene's material becomes on the lattice, said at start-up and in summary.json ("material" block):
/// E, nu asked, nu represented, density, total mass, the calibration at the scene's level, and the model error the
/// scene's contact carries according to the Hertz calibration of `palpate bench model` (sim/contact_model_error.h).

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/grid_hierarchy.h"
#include "core/result.h"
#include "core/scene.h"

namespace palpate {

/// The "material" block for summary.json; null when the scene uses the raw spring/mass keys.
nlohmann::json material_summary(const Scene& scene, const GridHierarchy& grid);

/// The start-up warnings for the scene's material (none when it is represented as asked): a Poisson ratio the
/// springs cannot take, and a body too soft to carry its own weight in the scene's gravity.
std::vector<std::string> material_warnings(const Scene& scene);

}  // namespace palpate
