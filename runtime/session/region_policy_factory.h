#pragma once
/// make_region_policy: the one place that knows the RegionPolicy implementations and picks one for a scene.

#include <memory>

#include "core/scene.h"
#include "runtime/session/frame_stats.h"
#include "runtime/session/model.h"
#include "runtime/session/region_policy.h"

namespace palpate {

/// The region of the scene's interaction mode: a CutRegion for cut, else a LocalRegion. scene, model and stats
/// must outlive it.
std::unique_ptr<RegionPolicy> make_region_policy(const Scene& scene, const Model& model, FrameStats* stats);

}  // namespace palpate
