#include "runtime/record/color_pass.h"

#include <algorithm>

#include "render/annotate.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/session.h"
#include "runtime/session/view_style.h"

namespace palpate {

bool needs_color_pass(const Scene& scene, bool render, DeviceDriver driver) {
  if (!render || driver != DeviceDriver::kScripted) return false;
  if (colors_by_strain(scene)) return !(scene.render.strain_range > 0.0);
  return colors_by_displacement(scene) && !(scene.render.color_range_m > 0.0);
}

double color_pass_range(const Scene& scene, const Model& model, const std::atomic<bool>* stop) {
  Scene pass = scene;
  pass.run_mode = RunMode::kLockstep;
  auto device = make_device(pass, "scripted");
  if (!device) return 0.0;
  struct Stopped {};
  try {
    Session session(pass, model, device.value().get());
    double most = 0.0;
    session.run_lockstep(pass.duration_s, [&](int64_t, double) {
      if (stop && stop->load(std::memory_order_relaxed)) throw Stopped{};
      // the surface's own displacement (the vertices the frame may move), not the lattice's: its nodes inside the
      // body, or sagging under gravity beside the touch, can move farther than any point a frame shows
      const FrameView view = session.stage().current_view();
      most = std::max(most, colors_by_strain(pass) ? ViewStyle::largest_strain(view)
                                                    : ViewStyle::largest_displacement_m(view));
    });
    return nice_ceil(most);
  } catch (const Stopped&) {
    return 0.0;
  }
}

}  // namespace palpate
