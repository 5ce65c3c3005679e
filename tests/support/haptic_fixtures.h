#pragma once
// Shared haptics test fixtures: a device held wherever the test puts it, and flat surface patches.

#include "core/triple_buffer.h"
#include "haptics/device.h"
#include "haptics/local_model.h"
#include "haptics/servo.h"

namespace palpate::test {

/// A device at a position (possibly non-finite) the test sets; remembers the last force written.
class FixedDevice final : public Device {
 public:
  const DeviceSpecs& specs() const noexcept override { return specs_; }
  bool read(double, DevicePose* out) noexcept override {
    if (!online) return false;
    out->pos_m = pos_m;
    out->buttons = buttons;
    return true;
  }
  void write_force(const Vec3& f) noexcept override { force_N = f; }
  DeviceSpecs specs_;
  Vec3 pos_m = Vec3::Zero();
  uint32_t buttons = 0;
  Vec3 force_N = Vec3::Zero();
  bool online = true;  ///< false: read() has no reading (a silent link)
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

/// Servo settings that render the published surface alone: coupling k_N_per_m, no damping, no ramp, no
/// passivity guard, no object response between frames.
inline ServoParams static_surface_params(double k_N_per_m) {
  ServoParams p;
  p.coupling_N_per_m = k_N_per_m;
  p.coupling_damping_Ns_per_m = 0;
  p.ramp_s = 0;
  p.passivity = false;
  p.force_model = ForceModel::kStaticSurface;
  return p;
}

}  // namespace palpate::test
