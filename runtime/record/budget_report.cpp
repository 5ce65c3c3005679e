#include "runtime/record/budget_report.h"

namespace palpate {

nlohmann::json budget_summary(const Scene& scene, const FrameStage& stage, bool lockstep) {
  if (scene.lattice.budget_ms <= 0.0) return nullptr;
  nlohmann::json j;
  j["budget_ms"] = scene.lattice.budget_ms;
  const FrameBudget* b = stage.budget();
  if (!b) {
    j["active"] = false;
    j["reason"] = lockstep ? "lockstep: no deadline, every frame steps at the scene's setting (reproducible)"
                           : "the integrator has nothing to trade";
    return j;
  }
  j["active"] = true;
  j["plan_ms"] = b->plan_ms();  // what the settings are planned to hold, leaving room for dearer frames
  j["clock"] = "wall (sim part of the frame: drain, cut, factor update, step, deform, normals, patch)";
  j["frames_over_budget"] = b->frames_over();
  j["changes"] = b->changes();
  j["frames_stepped_cheaper"] = b->frames_stepped_cheaper();
  j["error_source"] = kBudgetErrorSource;
  nlohmann::json settings = nlohmann::json::array();
  for (std::size_t i = 0; i < b->ladder().size(); ++i) {
    const BudgetSetting& s = b->ladder()[i];
    nlohmann::json r = {{"integrator", integrator_name(s.opts.kind)},
                        {"substeps", s.opts.substeps},
                        {"iterations", s.opts.iterations},
                        {"frames", b->frames_at()[i]}};
    if (s.error_node_rms_cell >= 0.0) r["error_node_rms_cell"] = s.error_node_rms_cell;
    else r["error_node_rms_cell"] = nullptr;
    settings.push_back(r);
  }
  j["settings"] = settings;
  return j;
}

}  // namespace palpate
