#include "runtime/session/region_policy_factory.h"

#include "runtime/session/cut_region.h"
#include "runtime/session/local_region.h"

namespace palpate {

std::unique_ptr<RegionPolicy> make_region_policy(const Scene& scene, const Model& model, FrameStats* stats) {
  if (scene.mode == InteractionMode::kCut) return std::make_unique<CutRegion>(scene, model, stats);
  return std::make_unique<LocalRegion>(scene, model, stats);
}

}  // namespace palpate
