#pragma once
// Shared haptics test fixtures: a device held wherever the test puts it, flat surface patches, and the rig of a servo
// (its device, sample queue, triple buffer and rates).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>

#include "core/spsc_queue.h"
#include "core/triple_buffer.h"
#include "haptics/devices/device.h"
#include "haptics/servo/local_model.h"
#include "haptics/servo/servo.h"

namespace palpate::test {

/// A device at a position (possibly non-finite) the test sets; remembers the last force written.
class FixedDevice final : public Device {
 public:
  const DeviceSpecs& specs() const noexcept override { return specs_; }
  bool read(double, DevicePose* out) noexcept override {
    if (!online) return false;
    out->pos_m = pos_m;
    out->buttons = buttons;
    out->controls = controls;
    return true;
  }
  void write_force(const Vec3& f) noexcept override { force_N = f; }
  DeviceSpecs specs_;
  Vec3 pos_m = Vec3::Zero();
  uint32_t buttons = 0;
  Vec3 force_N = Vec3::Zero();
  bool online = true;  ///< false: read() has no reading (a silent link)
  Controls controls{}; ///< what a person set (seq 0: nothing)
};

/// Adds a quad (a, b, c, d counter-clockwise seen from its outside) as two triangles with flat normals.
inline void add_quad(LocalModel* m, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 n = (b - a).cross(c - a).normalized();
  for (const auto& t : {std::array<Vec3, 3>{a, b, c}, std::array<Vec3, 3>{a, c, d}}) {
    m->tri_ids[m->num_triangles] = 10 + m->num_triangles;
    m->tri_m[m->num_triangles] = t;
    m->normal[m->num_triangles] = {n, n, n};
    ++m->num_triangles;
  }
}

/// Publishes a flat square floor z = 0 of half side half_m facing +z (triangles 10 and 11).
inline void publish_floor(TripleBuffer<LocalModel>* tb, double half_m = 0.05) {
  LocalModel& m = tb->write_buffer();
  m.num_triangles = 0;
  add_quad(&m, Vec3(-half_m, -half_m, 0), Vec3(half_m, -half_m, 0), Vec3(half_m, half_m, 0), Vec3(-half_m, half_m, 0));
  m.frame = 0;
  tb->publish();
}

/// The 1 kHz / 60 Hz rates every servo of the tests refers to (a servo keeps a reference to its rates).
inline const Rates kTestRates{};

/// The floor of publish_floor at height z_m, published as frame `frame` at t_s; blend: its corners were at from_z_m
/// the frame before and the servo moves them over one frame of kTestRates (blend_s), else no blend.
inline void publish_floor_at(TripleBuffer<LocalModel>* tb, double z_m, double from_z_m, int64_t frame, double t_s,
                             bool blend) {
  LocalModel& m = tb->write_buffer();
  m.num_triangles = 0;
  const double h = 0.05;
  add_quad(&m, Vec3(-h, -h, z_m), Vec3(h, -h, z_m), Vec3(h, h, z_m), Vec3(-h, h, z_m));
  for (int i = 0; i < m.num_triangles; ++i)
    for (int c = 0; c < 3; ++c) m.tri_from_m[i][c] = m.tri_m[i][c] + Vec3(0, 0, from_z_m - z_m);
  m.frame = frame;
  m.t_s = t_s;
  m.blend_s = blend ? kTestRates.frame_period_s() : 0.0;
  tb->publish();
}

/// Servo settings that render the published surface alone: coupling k_N_per_m, no damping, no ramp, no jump
/// limit, no passivity guard, no object response between frames.
inline ServoParams static_surface_params(double k_N_per_m) {
  ServoParams p;
  p.coupling_N_per_m = k_N_per_m;
  p.coupling_damping_Ns_per_m = 0;
  p.ramp_s = 0;
  p.jump_limit_N_per_tick = 0;
  p.passivity = false;
  p.force_model = ForceModel::kStaticSurface;
  return p;
}

/// A test's servo and what it trades with: its device (a Dev built from dev_args, or with Dev a reference, a device
/// the test holds), the sample queue of queue_size, the triple buffer the test publishes its surfaces into, the rates
/// (the servo keeps a reference to the rig's copy, which a test may change) and the servo of params p.
/// tick(i) runs tick i at i servo periods and drains the samples; make_servo(p) is another servo over the same parts.
template <typename Dev = FixedDevice>
struct ServoRig {
  template <typename... DevArgs>
  explicit ServoRig(const ServoParams& p, std::size_t queue_size = 4096, const Rates& servo_rates = kTestRates,
                    DevArgs&&... dev_args)
      : dev(std::forward<DevArgs>(dev_args)...), q(queue_size), rates(servo_rates), servo(make_servo(p)) {}
  std::unique_ptr<Servo> make_servo(const ServoParams& p) {
    return std::make_unique<Servo>(p, rates, &dev, &q, tb.get());
  }
  void tick(int64_t i) { tick(i, static_cast<double>(i) * rates.servo_period_s()); }
  void tick(int64_t i, double t_s) {
    servo->tick(i, t_s);
    drain();
  }
  void drain() {
    HapticSample s;
    while (q.try_pop(&s)) {
    }
  }
  Dev dev;
  SpscQueue<HapticSample> q;
  std::unique_ptr<TripleBuffer<LocalModel>> tb = std::make_unique<TripleBuffer<LocalModel>>();
  Rates rates;
  std::unique_ptr<Servo> servo;
};

/// A ServoRig of params p over the floor of publish_floor_at (z = 0 as frame 0; blend as given), its device held
/// wherever the test puts it (max force 100 N).
struct FloorRig : ServoRig<> {
  FloorRig(const ServoParams& p, bool blend) : ServoRig(p) {
    dev.specs_.max_force_N = 100;
    publish_floor_at(tb.get(), 0.0, 0.0, 0, 0.0, blend);
  }
};

}  // namespace palpate::test
