#pragma once
/// What a scene lets a person change while it runs (core/controls.h) and the scene each change makes: one place that
/// bounds and checks the page's controls before anything acts on them (the live view refuses what this refuses), and
/// that turns a control state into the scene a session starts again from.

#include <string>
#include <vector>

#include "core/controls.h"
#include "core/scene.h"

namespace palpate {

/// The bounds of a scene's controls. Plain data.
struct ControlLimits {
  std::vector<InteractionMode> modes;  ///< the modes the scene can switch to (its own first)
  double stiffness_lo = 1.0, stiffness_hi = 1.0;  ///< the stiffness factor's range (device.browser_stiffness_range)
  double radius_lo_m = 0.0, radius_hi_m = 0.0;    ///< the tool radius' range (device.browser_tool_radius_range_m)
  bool material = false;                          ///< the stiffness is a material's E (else a raw lattice's springs)
  double young_modulus_Pa = 0.0;                  ///< the scene's E (material)
};

/// The scene's own control state (seq 0).
Controls scene_controls(const Scene& scene);

/// The scene `base` runs as under `c`: its interaction mode (a sphere tool and a solved contact are the touch's, kept
/// only there; colours by strain are not drawn in cut mode), its material's stiffness times c.stiffness_scale (E, or
/// a raw lattice's springs; damping as the scene sets it), its tool radius c.tool_radius_m (> 0).
Scene scene_with_controls(const Scene& base, const Controls& c);

/// The limits of `base`'s controls: the modes whose scene (scene_with_controls) has no conflict (scene_conflict), and
/// the ranges its keys state.
ControlLimits control_limits(const Scene& base);

/// Why `c` is refused for `base` (a mode it cannot switch to, a value out of its range, naming both), or "".
std::string refuse_controls(const Scene& base, const Controls& c);

}  // namespace palpate
