#include "runtime/session/session.h"

#include "core/scene_controls.h"
#include "runtime/session/device_factory.h"

namespace palpate {

Session::Session(const Scene& scene, const Model& model, Device* device, const SessionOutputs& outputs)
    : Session(scene, model, device, servo_params_for(scene, device->specs()), outputs) {}

Session::Session(const Scene& scene, const Model& model, Device* device, const ServoParams& params,
                 const SessionOutputs& outputs)
    : scene_(scene),
      model_(model),
      device_(device),
      outputs_(outputs),
      params_(params),
      samples_(kSessionSampleQueue),
      local_model_(std::make_unique<TripleBuffer<LocalModel>>()),
      servo_(params_, scene.rates, device, &samples_, local_model_.get()),
      applied_(servo_.controls()) {
  stage_.emplace(scene, model, &samples_, local_model_.get(), outputs.renderer, outputs.writer, outputs.log);
  stage_->set_video(outputs.video);
  stage_->set_live(outputs.live);
}

void Session::frame_at(int64_t index, double t_s, bool block_on_writer, int64_t drain_to_tick) {
  stage_->frame(index, t_s, block_on_writer, drain_to_tick);
  // (a copy: the stage it comes from is replaced)
  if (const Controls c = stage_->latest_controls(); c.seq > applied_.seq) restart(c, index, t_s);
}

void Session::use_budget(BudgetClock* clock) {
  budget_clock_ = clock;
  stage_->use_budget(clock);
}

void Session::keep_deadlines() {
  deadlines_ = true;
  stage_->keep_deadlines();
}

void Session::restart(Controls c, int64_t frame, double t_s) {
  applied_ = c;
  changes_.push_back({frame, t_s, c});
  scenes_.push_back(scene_with_controls(scene_, c));
  FrameStats stats = stage_->stats();
  stage_.reset();
  stage_.emplace(scenes_.back(), model_, &samples_, local_model_.get(), outputs_.renderer, outputs_.writer, outputs_.log);
  stage_->adopt_stats(std::move(stats));
  stage_->set_controls_seq(c.seq);
  stage_->set_video(outputs_.video);
  stage_->set_live(outputs_.live);
  if (budget_clock_) stage_->use_budget(budget_clock_);
  if (deadlines_) stage_->keep_deadlines();
}

}  // namespace palpate
