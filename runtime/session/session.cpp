#include "runtime/session/session.h"

#include "runtime/session/device_factory.h"

namespace palpate {

Session::Session(const Scene& scene, const Model& model, Device* device, const SessionOutputs& outputs)
    : Session(scene, model, device, servo_params_for(scene, device->specs()), outputs) {}

Session::Session(const Scene& scene, const Model& model, Device* device, const ServoParams& params,
                 const SessionOutputs& outputs)
    : scene_(scene),
      device_(device),
      params_(params),
      samples_(kSessionSampleQueue),
      local_model_(std::make_unique<TripleBuffer<LocalModel>>()),
      servo_(params_, scene.rates, device, &samples_, local_model_.get()),
      stage_(scene, model, &samples_, local_model_.get(), outputs.renderer, outputs.writer, outputs.log) {
  stage_.set_video(outputs.video);
  stage_.set_live(outputs.live);
}

}  // namespace palpate
