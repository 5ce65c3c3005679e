#pragma once
/// What a scene's material becomes on the lattice, said at start-up and in summary.json ("material" block):
/// E, nu asked, nu represented, density, total mass, the calibration at the scene's level, and the model error the
/// scene's contact carries according to the Hertz calibration of `palpate bench model` (sim/contact/contact_model_error.h).

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/grid_hierarchy.h"
#include "core/result.h"
#include "core/scene.h"
#include "core/tri_mesh.h"
#include "runtime/session/model.h"

namespace palpate {

/// The "material" block for summary.json; null when the scene uses the raw spring/mass keys.
nlohmann::json material_summary(const Scene& scene, const GridHierarchy& grid);

/// One line for the end of a recording from summary.json's "material" block: the model, E, nu asked and
/// represented, density, cell edge, and the force error the scene's contact carries by the calibration ("" for null).
std::string material_line(const nlohmann::json& material);

/// The start-up warnings for the scene's material (none when it is represented as asked): a Poisson ratio the
/// springs cannot take.
std::vector<std::string> material_warnings(const Scene& scene);

/// Once the model is loaded: the warning for a body too soft to carry its own weight in the scene's gravity, its
/// height the rest mesh's extent along g (sim/material/material.h self_weight_warning); "" when it can.
std::string self_weight_notice(const Scene& scene, const std::vector<Vec3>& rest_vertices_m);

/// Once the model is loaded: the warning for a lattice finer than the mesh's triangles in touch and pull (the surface
/// the tool meets moves only at the triangles' corners, so finer cells add cost, not accuracy, and a push lands on the
/// corners of the triangle it meets): when the median of the rest mesh's triangles' longest edges is more than
/// kCoarseMeshEdgeCells of the finest cells (lattice.refine.level when refined); "" otherwise.
std::string mesh_resolution_notice(const Scene& scene, const TriMesh& rest, const GridHierarchy& grid);

}  // namespace palpate
