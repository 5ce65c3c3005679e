// palpate.Session: one run of the pipeline stepped from Python tick by tick or frame by frame, on the lockstep clock
// `palpate record` uses, so the same scene and inputs reach the same state hash.
#include <cmath>
#include <memory>
#include <string>

#include <pybind11/stl.h>

#include "python/bindings.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/haptic_log.h"
#include "runtime/session/model.h"
#include "runtime/session/relative_keys.h"
#include "runtime/session/session.h"

namespace py = pybind11;

namespace palpate::python {
namespace {

// A device whose handle is where Python last put it; it keeps the force the servo sent.
class HeldDevice final : public Device {
 public:
  explicit HeldDevice(const DeviceSpecs& specs) : specs_(specs) {}
  const DeviceSpecs& specs() const noexcept override { return specs_; }
  bool read(double, DevicePose* out) noexcept override {
    *out = pose_;
    return true;
  }
  void write_force(const Vec3& f) noexcept override { force_N_ = f; }
  nlohmann::json report() const override { return {{"driver", "python"}}; }
  DevicePose pose_;
  Vec3 force_N_ = Vec3::Zero();

 private:
  DeviceSpecs specs_;
};

py::array_t<double> vec3(const Vec3& v) {
  py::array_t<double> a(3);
  for (int i = 0; i < 3; ++i) a.mutable_data()[i] = v[i];
  return a;
}

py::array_t<double> points(const std::vector<Vec3>& p) {
  py::array_t<double> a({static_cast<py::ssize_t>(p.size()), py::ssize_t{3}});
  double* d = a.mutable_data();
  for (std::size_t i = 0; i < p.size(); ++i)
    for (int k = 0; k < 3; ++k) d[3 * i + static_cast<std::size_t>(k)] = p[i][k];
  return a;
}

const char* contact_name(ContactState c) {
  switch (c) {
    case ContactState::kTouch: return "touch";
    case ContactState::kGrab: return "grab";
    case ContactState::kCut: return "cut";
    case ContactState::kFree: break;
  }
  return "free";
}

class PySession {
 public:
  PySession(const Scene& scene, const std::string& device) : scene_(scene) {
    auto model = load_model(scene_);
    if (!model) throw RunFailure(model.error().message);
    model_ = std::make_unique<Model>(std::move(model).value());
    if (auto st = resolve_relative_keys(*model_, &scene_); !st) throw RunFailure(st.error().message);
    if (device == "python") {
      // a handle a program moves, as a linked device is: the device's own damping, not a scripted hand's
      auto held = std::make_unique<HeldDevice>(device_specs_for(scene_, DeviceDriver::kShm));
      held_ = held.get();
      held_->pose_.pos_m = scene_.trajectory.empty() ? Vec3::Zero() : scene_.trajectory.front().pos_m;
      device_ = std::move(held);
    } else {
      auto d = make_device(scene_, device);
      if (!d) throw RunFailure(d.error().message);
      if (d.value()->schedule() != nullptr)
        throw RunFailure("device '" + device + "': a replayed run has its own order; use palpate.record");
      device_ = std::move(d).value();
    }
    log_.keep_samples(&kept_);
    SessionOutputs outputs;
    outputs.log = &log_;
    session_ = std::make_unique<Session>(scene_, *model_, device_.get(), outputs);
  }

  // the lockstep loop's order: every frame due at the tick's time runs before it
  void tick() {
    if (finished_) throw RunFailure("the session has finished (run() ended it)");
    const Rates& r = scene_.rates;
    const double t = r.tick_time_s(next_tick_);
    while (r.frame_time_s(next_frame_) <= t + 1e-12) session_->frame(next_frame_++, true);
    session_->tick(next_tick_++, t);
  }
  // ticks up to the one before the next frame is due: one frame period of the hand
  void step(int frames) {
    const Rates& r = scene_.rates;
    for (int f = 0; f < frames; ++f) {
      do tick();
      while (r.frame_time_s(next_frame_) > r.tick_time_s(next_tick_) + 1e-12);
    }
  }
  // as `palpate record` runs duration_s: its ticks, the frames left, the samples drained
  void run(double duration_s) {
    const Rates& r = scene_.rates;
    const double d = duration_s > 0.0 ? duration_s : scene_.duration_s;
    while (next_tick_ < r.ticks(d)) tick();
    for (; next_frame_ < r.frames(d); ++next_frame_) session_->frame(next_frame_, true);
    session_->finish();
    finished_ = true;
  }
  void set_pose(const std::vector<double>& pos_m, uint32_t buttons) {
    if (held_ == nullptr) throw RunFailure("set_pose: this session's device is the scene's; open it with device='python'");
    if (pos_m.size() != 3) throw SceneFailure("set_pose: a position is 3 numbers (x, y, z in metres)");
    held_->pose_.pos_m = Vec3(pos_m[0], pos_m[1], pos_m[2]);
    held_->pose_.buttons = buttons;
  }
  py::dict samples() {
    py::dict d = log_arrays(kept_);
    kept_.clear();
    return d;
  }
  const HapticSample& last() const { return session_->servo().last_sample(); }
  py::object nodes() const {
    const auto& lat = session_->stage().lattice();
    if (!lat) return py::none();
    return points(lat->x_m);
  }
  py::object rest_nodes() const {
    const auto& lat = session_->stage().lattice();
    if (!lat) return py::none();
    return points(lat->rest_m);
  }

  Scene scene_;
  std::unique_ptr<Model> model_;
  std::unique_ptr<Device> device_;
  HeldDevice* held_ = nullptr;
  std::vector<HapticSample> kept_;
  HapticLog log_;
  std::unique_ptr<Session> session_;
  int64_t next_tick_ = 0, next_frame_ = 0;
  bool finished_ = false;
};

}  // namespace

void bind_session(py::module_& m) {
  using release = py::call_guard<py::gil_scoped_release>;
  py::class_<PySession>(m, "NativeSession")
      .def(py::init<const Scene&, const std::string&>(), py::arg("scene"), py::arg("device") = "")
      .def("tick", &PySession::tick, release())
      .def("step", &PySession::step, py::arg("frames") = 1, release())
      .def("run", &PySession::run, py::arg("duration_s") = 0.0, release())
      .def("set_pose", &PySession::set_pose, py::arg("pos_m"), py::arg("buttons") = 0)
      .def("samples", &PySession::samples)
      .def_property_readonly("ticks", [](const PySession& s) { return s.next_tick_; })
      .def_property_readonly("frames", [](const PySession& s) { return s.next_frame_; })
      .def_property_readonly("time_s", [](const PySession& s) { return s.last().t_s; })
      .def_property_readonly("finished", [](const PySession& s) { return s.finished_; })
      .def_property_readonly("force", [](const PySession& s) { return vec3(s.last().force_N); })
      .def_property_readonly("proxy", [](const PySession& s) { return vec3(s.last().proxy_pos_m); })
      .def_property_readonly("tool", [](const PySession& s) { return vec3(s.last().tool_pos_m); })
      .def_property_readonly("contact", [](const PySession& s) { return std::string(contact_name(s.last().contact)); })
      .def_property_readonly("nodes", &PySession::nodes)
      .def_property_readonly("rest_nodes", &PySession::rest_nodes)
      .def_property_readonly("vertices", [](const PySession& s) { return points(s.session_->stage().vertices_m()); })
      .def_property_readonly("state_hash", [](const PySession& s) { return s.session_->stage().state_hash(); });
}

}  // namespace palpate::python
