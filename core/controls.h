#pragma once
/// Controls: what a person may change while a run goes on (the browser page's controls) — the interaction mode, the
/// material's stiffness as a factor of the scene's, a sphere tool's radius, and a reset. Plain data: it rides with
/// every device pose (DevicePose), every servo sample (HapticSample) and every haptic.csv row, so a replay changes
/// what the recording changed at the same tick. Which values a scene allows: core/scene_controls.h.

#include <cstdint>

#include "core/scene_enums.h"

namespace palpate {

/// One state of the controls. seq 0 is the scene's own (nothing changed yet); every change the session must act on
/// (a new value or a reset) comes with a larger seq. Plain data.
struct Controls {
  int64_t seq = 0;                               ///< 0: the scene as loaded; increases with every change
  InteractionMode mode = InteractionMode::kTouch;///< touch, pull or cut
  double stiffness_scale = 1.0;                  ///< the material's stiffness (E, or a raw lattice's springs) times this
  double tool_radius_m = 0.0;                    ///< the tool's radius (a sphere tool's contact; drawn for the others)
  int64_t resets = 0;                            ///< resets asked for so far
};

}  // namespace palpate
