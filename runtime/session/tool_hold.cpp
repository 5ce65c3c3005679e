#include "runtime/session/tool_hold.h"

#include "core/thread_cpu.h"

#include <algorithm>
#include <cmath>
#include <ctime>

#include "core/rates.h"
#include "haptics/devices/device.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {

// A handle moved straight to a position and clamped there: records the force it is sent.
class ClampedDevice final : public Device {
 public:
  ClampedDevice(const DeviceSpecs& specs, const Vec3& from_m, const Vec3& to_m, double approach_s)
      : specs_(specs), from_m_(from_m), to_m_(to_m), approach_s_(approach_s) {}
  const DeviceSpecs& specs() const noexcept override { return specs_; }
  bool read(double t_s, DevicePose* out) noexcept override {
    const double u = approach_s_ > 0.0 ? std::clamp(t_s / approach_s_, 0.0, 1.0) : 1.0;
    *out = pose_;
    out->pos_m = from_m_ + u * (to_m_ - from_m_);
    return true;
  }
  void write_force(const Vec3& f) noexcept override { force_N_ = f; }
  const Vec3& force_N() const { return force_N_; }

 private:
  DeviceSpecs specs_;
  Vec3 from_m_, to_m_;
  double approach_s_;
  DevicePose pose_;
  Vec3 force_N_ = Vec3::Zero();
};

// The median of *v (reordered), 0 when empty.
double median(std::vector<double>* v) {
  if (v->empty()) return 0.0;
  const auto mid = v->begin() + static_cast<std::ptrdiff_t>(v->size() / 2);
  std::nth_element(v->begin(), mid, v->end());
  return *mid;
}

}  // namespace

Result<ToolHoldResult> hold_tool(const Scene& scene, const Model& model, const ToolHoldOptions& o) {
  const Rates& rates = scene.rates;
  DeviceSpecs specs;
  specs.max_force_N = scene.device.max_force_N;
  specs.max_stiffness_N_per_m = scene.device.max_stiffness_N_per_m;
  specs.workspace_half_m = scene.device.workspace_half_m;
  ClampedDevice dev(specs, o.approach_s > 0.0 ? o.start_pos_m : o.device_pos_m, o.device_pos_m, o.approach_s);
  Session session(scene, model, &dev);
  const FrameStage& stage = session.stage();
  const Servo& servo = session.servo();
  ToolHoldResult r;
  const int64_t max_frames = static_cast<int64_t>(std::ceil(o.max_s * rates.frame_hz));
  int64_t tick = 0;
  Vec3 prev_mean = Vec3::Zero();
  Vec3 frame_means[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
  int still = 0;
  std::vector<double> sim_ms;
  // the lockstep order of Session::run_lockstep, driven frame by frame here: the run ends once the object rests,
  // judged between a frame's ticks and the next frame
  for (int64_t f = 0; f < max_frames; ++f) {
    const double t0 = thread_cpu_ms();
    const int64_t moves = stage.stats().region_moves;
    session.frame_at(f, static_cast<double>(f) / rates.frame_hz, false);
    sim_ms.push_back(thread_cpu_ms() - t0);
    if (o.record_ticks && stage.stats().region_moves != moves) r.region_move_ticks.push_back(tick);
    // the servo ticks due before the next frame (16 or 17 at 1 kHz and 60 Hz: the scene's rates)
    const int64_t until = static_cast<int64_t>(std::ceil((f + 1) * rates.servo_hz / rates.frame_hz - 1e-9));
    Vec3 sum = Vec3::Zero();
    int64_t ticks = 0;
    for (; tick < until; ++tick, ++ticks) {
      session.tick(tick, static_cast<double>(tick) / rates.servo_hz);
      sum += dev.force_N();
      if (o.record_ticks) r.tick_force_N.push_back(dev.force_N());
    }
    r.frames = f + 1;
    const Vec3 mean = ticks > 0 ? Vec3(sum / static_cast<double>(ticks)) : Vec3::Zero();
    frame_means[f % 3] = mean;
    double speed = 0.0, moved = 0.0;
    if (stage.lattice()) {
      const Lattice& lat = *stage.lattice();
      for (std::size_t i = 0; i < lat.num_nodes(); ++i) {
        speed = std::max(speed, lat.v_m_per_s[i].norm());
        moved = std::max(moved, (lat.x_m[i] - lat.rest_m[i]).norm());
      }
    }
    r.max_node_speed_m_per_s = speed;
    const double push = mean.norm();
    const bool steady = push > 0.0 && std::abs(mean.dot(prev_mean) / push - push) <= o.rest_force_rel * push;
    prev_mean = mean;
    // at rest once the object has been touched, has stopped, and the push holds, three frames running
    still = f / rates.frame_hz >= o.approach_s && stage.lattice() && steady && speed / rates.frame_hz <= o.rest_move_rel * moved ? still + 1 : 0;
    if (still >= 3) {
      r.at_rest = true;
      break;
    }
  }
  r.force_N = (frame_means[0] + frame_means[1] + frame_means[2]) / 3.0;
  session.finish();
  const HapticSample& s = servo.last_sample();
  r.proxy_m = s.proxy_pos_m;
  r.contact_tri = s.contact_tri;
  r.contact_bary = s.contact_bary;
  if (stage.lattice()) {
    r.nodes = stage.lattice()->num_nodes();
    r.springs = stage.lattice()->springs.size();
  }
  r.force_nodes = stage.stats().force_nodes;
  r.solved_frames = stage.stats().solved_contact_frames;
  if (!sim_ms.empty()) {
    std::nth_element(sim_ms.begin(), sim_ms.begin() + static_cast<std::ptrdiff_t>(sim_ms.size() / 2), sim_ms.end());
    r.sim_ms_p50 = sim_ms[sim_ms.size() / 2];
  }
  std::vector<double> step_ms = stage.stats().step_cpu_ms, cg;
  for (const FrameProfile& p : stage.stats().profile)
    if (p.iterations > 0) cg.push_back(p.cg_iterations);
  r.step_ms_p50 = median(&step_ms);
  r.cg_iterations_p50 = median(&cg);
  r.substeps = stage.stats().substeps_total;
  r.region_moves = stage.stats().region_moves;
  r.vertices_m = stage.vertices_m();
  return r;
}

}  // namespace palpate
