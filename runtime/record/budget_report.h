#pragma once
/// The frame budget's block in summary.json ("budget"): which step settings ran, for how many frames, and the
/// time-integration error each carries.

#include <nlohmann/json.hpp>

#include "core/scene.h"
#include "runtime/session/frame_stage.h"

namespace palpate {

/// The "budget" block; null when the scene sets no lattice.budget_ms. A lockstep run has no deadline (frames wait
/// for each other) and keeps the scene's setting, so its state hash stays reproducible: the block says so.
nlohmann::json budget_summary(const Scene& scene, const FrameStage& stage, bool lockstep);

}  // namespace palpate
