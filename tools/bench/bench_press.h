#pragma once
/// The solved press of a scene's tool: the scene's lattice (at each asked level) and its tool treated as a rigid
/// sphere of the tool's radius (a point tool too), the sphere free on the device's coupling spring in series with the
/// hand's, anchored at the trajectory's deepest point, solved jointly with the lattice (sim/contact/sphere_contact.h). The
/// static figure a recording holds there, with the contact found from the deformation rather than a load by formula.

#include <cstddef>
#include <string>
#include <vector>

#include "core/result.h"

namespace palpate {

/// One level of the press. Plain data.
struct PressRow {
  int level = 0;                   ///< lattice level
  int radius_cells = 0;            ///< region radius used (the same physical size at every level)
  std::size_t nodes = 0;           ///< lattice nodes
  int samples_per_edge = 0;        ///< contact samples per cell edge (spacing at most half the tool's radius)
  double force_N = 0.0;            ///< the push on the tool at equilibrium (up)
  double depth_m = 0.0;            ///< the sphere's lowest point below the rest top
  int active = 0;                  ///< samples in contact
  int iterations = 0;              ///< Newton steps over all increments
  double max_penetration_m = 0.0;  ///< the penalty's give
  std::string failure;             ///< why the solve stopped (empty: it converged)
};

/// Loads scene_path, sets material.young_modulus_Pa (when > 0), and for each level the lattice level, a region radius
/// of 3 cells at levels <= 4 and 3 * 2^(level - 4) above (the same physical size), grid levels max(5, level); the
/// anchor goes from the sphere resting on the top to the trajectory's lowest key in 8 increments. A level whose
/// solve fails gets its row with the reason in `failure`; errors name the scene and level when it cannot be built.
Result<std::vector<PressRow>> run_solved_press(const std::string& scene_path, double young_modulus_Pa,
                                               const std::vector<int>& levels);

}  // namespace palpate
