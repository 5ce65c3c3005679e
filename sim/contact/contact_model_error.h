#pragma once
/// The model error a scene's contact carries, from the Hertz calibration of `palpate bench model` (a sphere of
/// radius 10 cm pressed 0.25 mm into an 8 x 8 x 4 cm block, contact radius 5 mm, at levels 3-6: contact radius 0.25
/// to 2 cells), one table with Hertz's pressure prescribed and one with the contact solved. The table holds those measured force errors per material model and Poisson ratio; a scene's error
/// is read off it at the scene's contact radius over its cell edge. Not measured in the scene's own run. Pure
/// functions; any thread.

#include <string>

#include "core/scene.h"

namespace palpate {

/// What the calibration says about one scene's contact. Plain data.
struct ContactModelError {
  bool defined = false;              ///< false for a point tool (a point load has no continuum limit)
  double contact_radius_cells = 0.0; ///< the contact radius taken (the sphere tool's radius: its widest patch) over
                                     ///< the cell edge
  double hertz_force_error = 0.0;    ///< the lattice's force over Hertz's, minus 1, interpolated in the table
  bool within_calibration = false;   ///< the contact radius and nu lie inside the measured range (else the nearest)
  std::string basis;                 ///< what the figure is and where it comes from, in words
};

/// The calibration's figure for a tool (sphere_tool with tool_radius_m, else a point) on `material` at cell cell_m;
/// solved: the calibration with the contact solved under the sphere (device.contact "solved"), else with Hertz's
/// pressure prescribed.
ContactModelError contact_model_error(const MaterialSpec& material, bool sphere_tool, double tool_radius_m,
                                      double cell_m, bool solved = false);

}  // namespace palpate
