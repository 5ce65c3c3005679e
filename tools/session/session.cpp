#include "tools/session/session.h"

#include "tools/session/device_factory.h"

namespace palpate {

Session::Session(const Scene& scene, const Model& model, const Rates& rates, Device* device,
                 const SessionOutputs& outputs)
    : Session(scene, model, rates, device, servo_params_for(scene, device->specs(), rates.servo_hz), outputs) {}

Session::Session(const Scene& scene, const Model& model, const Rates& rates, Device* device, const ServoParams& params,
                 const SessionOutputs& outputs)
    : rates_(rates),
      params_(params),
      samples_(kSessionSampleQueue),
      local_model_(std::make_unique<TripleBuffer<LocalModel>>()),
      servo_(params_, device, &samples_, local_model_.get()),
      stage_(scene, model, &samples_, local_model_.get(), outputs.renderer, outputs.writer, outputs.log) {
  stage_.set_step_dt(rates_.frame_period_s());
  stage_.set_video(outputs.video);
  stage_.set_live(outputs.live);
}

}  // namespace palpate
