// The servo against a stalled simulation: the hand presses the cube at the device's stiffness limit while the
// 60 Hz stage publishes nothing for 200 ms; the handle must not oscillate with growing amplitude. A stall leaves
// the servo's local model valid (stale, not wrong), so the loop stays passive by itself: the control run without
// the passivity guard settles the same way, and the guard, run beside it, never acts (it dissipates only energy
// the port created: tests/haptics/force/passivity_test.cpp drives it where it must).
#include <gtest/gtest.h>

#include <algorithm>

#include "core/scene.h"
#include "haptics/devices/scripted_device.h"
#include "support/fixtures.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/model.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {

struct Swing {
  double before = 0, during = 0, after = 0, max_force_N = 0;
  int64_t guard_activations = 0;
};

Swing run(bool passivity) {
  Scene scene = load_scene(test::source_path("scenes/cube_press.json")).value();
  scene.device.coupling_N_per_m = scene.device.max_stiffness_N_per_m;  // at the limit
  const Model model = load_model(scene).value();
  DeviceSpecs specs;
  ScriptedDevice dev(specs, scene.hand, scene.trajectory);
  // the servo the scene asks for on this device (the coupling at its 700 N/m limit), with or without the guard
  ServoParams p = servo_params_for(scene, specs);
  p.passivity = passivity;
  Session session(scene, model, &dev, p);
  const Servo& servo = session.servo();
  Swing s;
  auto track = [](double* swing, double lo, double hi) { *swing = std::max(*swing, hi - lo); };
  double lo[3] = {1, 1, 1}, hi[3] = {-1, -1, -1};
  // the lockstep order driven tick by tick, so the frames due during the stall can be left out
  int64_t frame = 0;
  for (int64_t i = 0; i < 1000; ++i) {
    const double t = i * 1e-3;
    const bool stalled = t >= 0.5 && t < 0.7;
    if (frame / 60.0 <= t + 1e-12) {
      if (!stalled) session.frame_at(frame, t, false);
      ++frame;
    }
    session.tick(i, t);
    const double z = servo.last_sample().tool_pos_m.z();
    const int w = t < 0.5 ? (t >= 0.35 ? 0 : -1) : t < 0.7 ? 1 : (t >= 0.85 ? 2 : -1);
    if (w >= 0) lo[w] = std::min(lo[w], z), hi[w] = std::max(hi[w], z);
    s.max_force_N = std::max(s.max_force_N, servo.last_sample().force_N.norm());
  }
  s.guard_activations = servo.counters().passivity_activations;
  track(&s.before, lo[0], hi[0]);
  track(&s.during, lo[1], hi[1]);
  track(&s.after, lo[2], hi[2]);
  return s;
}

TEST(Stall, HandleSettlesAfterA200msSimStallAtTheStiffnessLimitWithoutTheGuardActing) {
  const Swing guarded = run(true), control = run(false);
  for (const Swing* s : {&guarded, &control}) {
    EXPECT_LE(s->max_force_N, DeviceSpecs{}.max_force_N + 1e-12);
    // the press has settled before the stall; the swing afterwards is no larger than during the stall
    EXPECT_LE(s->after, std::max(s->during, 1e-4)) << "before " << s->before << " during " << s->during << " after " << s->after;
    EXPECT_LT(s->after, 2e-3);
  }
  // the stall creates no energy at the port: the guard stays idle and the two runs are the same run
  EXPECT_EQ(guarded.guard_activations, 0);
  EXPECT_EQ(guarded.after, control.after);
  EXPECT_EQ(guarded.during, control.during);
  RecordProperty("swing_um", std::to_string(guarded.before * 1e6) + "/" + std::to_string(guarded.during * 1e6) + "/" +
                                 std::to_string(guarded.after * 1e6));
}

}  // namespace
}  // namespace palpate
