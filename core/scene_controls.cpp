#include "core/scene_controls.h"

#include <cmath>

#include "core/scene_reader.h"

namespace palpate {

using scene_reader::fmt_num;

Controls scene_controls(const Scene& scene) {
  Controls c;
  c.mode = scene.mode;
  c.tool_radius_m = scene.device.tool_radius_m;
  return c;
}

Scene scene_with_controls(const Scene& base, const Controls& c) {
  Scene s = base;
  s.mode = c.mode;
  const bool touch = c.mode == InteractionMode::kTouch;
  s.device.sphere_tool = touch && base.device.sphere_tool;
  s.device.solved_contact = touch && base.device.solved_contact;
  if (c.mode == InteractionMode::kCut && colors_by_strain(base)) s.render.color = RenderColor::kDisplacement;
  if (c.tool_radius_m > 0.0) s.device.tool_radius_m = c.tool_radius_m;
  const double k = c.stiffness_scale > 0.0 && std::isfinite(c.stiffness_scale) ? c.stiffness_scale : 1.0;
  LatticeSpec& l = s.lattice;
  if (l.material.enabled) {
    l.material.young_modulus_Pa *= k;
  } else {
    l.structural_N_per_m *= k;
    l.shear_N_per_m *= k;
    l.bend_N_per_m *= k;
  }
  s.warnings.clear();
  return s;
}

ControlLimits control_limits(const Scene& base) {
  ControlLimits l;
  l.modes.push_back(base.mode);
  for (const InteractionMode m : {InteractionMode::kTouch, InteractionMode::kPull, InteractionMode::kCut}) {
    if (m == base.mode) continue;
    Controls c = scene_controls(base);
    c.mode = m;
    if (scene_conflict(scene_with_controls(base, c)).empty()) l.modes.push_back(m);
  }
  l.stiffness_lo = base.device.browser_stiffness_lo;
  l.stiffness_hi = base.device.browser_stiffness_hi;
  const double r = base.device.tool_radius_m;
  l.radius_lo_m = base.device.browser_radius_hi_m > 0.0 ? base.device.browser_radius_lo_m : 0.5 * r;
  l.radius_hi_m = base.device.browser_radius_hi_m > 0.0 ? base.device.browser_radius_hi_m : 2.0 * r;
  l.material = base.lattice.material.enabled;
  l.young_modulus_Pa = base.lattice.material.young_modulus_Pa;
  return l;
}

std::string refuse_controls(const Scene& base, const Controls& c) {
  const ControlLimits l = control_limits(base);
  bool offered = false;
  for (const InteractionMode m : l.modes) offered = offered || m == c.mode;
  if (!offered) {
    Controls want = scene_controls(base);
    want.mode = c.mode;
    const std::string why = scene_conflict(scene_with_controls(base, want));
    return std::string("mode '") + mode_name(c.mode) + "' is not one this scene can switch to" +
           (why.empty() ? std::string() : " (" + why + ")");
  }
  if (!(c.stiffness_scale >= l.stiffness_lo && c.stiffness_scale <= l.stiffness_hi))
    return "stiffness " + fmt_num(c.stiffness_scale) + " is outside the scene's range [" + fmt_num(l.stiffness_lo) + ", " +
           fmt_num(l.stiffness_hi) + "] (device.browser_stiffness_range)";
  // (the page writes the radius in micrometres: a hair's rounding is not a refusal)
  if (!(c.tool_radius_m >= l.radius_lo_m * (1.0 - 1e-6) && c.tool_radius_m <= l.radius_hi_m * (1.0 + 1e-6)))
    return "tool radius " + fmt_num(c.tool_radius_m * 1e3) + " mm is outside the scene's range [" + fmt_num(l.radius_lo_m * 1e3) +
           ", " + fmt_num(l.radius_hi_m * 1e3) + "] mm (device.browser_tool_radius_range_m)";
  return "";
}

}  // namespace palpate
