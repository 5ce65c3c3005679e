// Google Benchmark: the cost of one servo tick in contact (god-object touch, multirate model) on the bunny and on
// the bunny subdivided to 235k triangles — the servo only ever sees the bounded patch near the tool, so the cost
// should not grow with the mesh.
#include <benchmark/benchmark.h>

#include "core/scene.h"
#include "runtime/session/model.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {

/// A device held still at a point just under the bunny's back, after crossing the surface.
class HeldDevice final : public Device {
 public:
  const DeviceSpecs& specs() const noexcept override { return specs_; }
  bool read(double, DevicePose* out) noexcept override {
    out->pos_m = pos_m;
    return true;
  }
  void write_force(const Vec3&) noexcept override {}
  DeviceSpecs specs_;
  Vec3 pos_m = Vec3::Zero();
};

void BM_ServoTickInContact(benchmark::State& state) {
  Scene scene = load_scene("scenes/bunny_touch.json").value();
  Model model = load_model(scene).value();
  // midpoint subdivision keeps the surface; rebuild grid and bindings on the finer mesh
  for (int64_t i = 0; i < state.range(0); ++i) model.rest = subdivide_midpoint(model.rest);
  model.grid = GridHierarchy::build(model.rest, model.normalization.cube, scene.grid_levels).value();
  model.bindings = bind_vertices(model.grid, scene.lattice.level, model.rest.vertices_m);
  scene.trajectory = {{0.0, Vec3(0.015, -0.01, 0.0135), false}};
  HeldDevice dev;
  // the default servo without its ramp, at 1 kHz; one frame publishes the patch around the tool
  ServoParams p;
  p.ramp_s = 0;
  Session session(scene, model, &dev, p);
  session.frame(0, false);
  Servo& servo = session.servo();
  dev.pos_m = Vec3(0.015, -0.01, 0.03);
  servo.tick(0, 0.0);
  dev.pos_m = Vec3(0.015, -0.01, 0.0135);  // ~1 mm under the surface
  int64_t tick = 1;
  HapticSample sink;
  for (auto _ : state) {
    servo.tick(tick, static_cast<double>(tick) * 1e-3);
    ++tick;
    if ((tick & 1023) == 0)
      while (session.samples().try_pop(&sink)) {
      }
  }
  state.counters["mesh_triangles"] = static_cast<double>(model.rest.num_triangles());
  state.counters["patch_triangles"] = session.local_model().read().num_triangles;
  state.counters["in_contact"] = servo.last_sample().contact == ContactState::kTouch ? 1 : 0;
}
BENCHMARK(BM_ServoTickInContact)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMicrosecond)->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace palpate

BENCHMARK_MAIN();
