#include "runtime/session/contact_report.h"

#include <cmath>
#include <cstdio>
#include <limits>

#include "runtime/session/surface_queries.h"

namespace palpate {
namespace {

std::string mm(double d_m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, d_m >= 0.01 ? "%.0f mm" : "%.1f mm", 1e3 * d_m);
  return buf;
}

}  // namespace

std::string no_contact_note(const Scene& scene, const Model& model, const std::vector<ReplayRow>& rows) {
  char head[64];
  std::snprintf(head, sizeof head, "no contact in %.1f s: ", scene.duration_s);
  // which rows could have made contact: pull grabs on a press, the blade cuts while the button is held
  double closest_m = std::numeric_limits<double>::infinity();
  Vec3 last_p = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  double last_d = 0.0;
  int64_t candidates = 0;
  uint32_t prev_buttons = 0;
  for (const ReplayRow& r : rows) {
    const bool pressed = (r.buttons & 1u) != 0;
    const bool counts = scene.mode == InteractionMode::kPull ? pressed && !(prev_buttons & 1u)
                        : scene.mode == InteractionMode::kCut ? pressed
                                                              : true;
    prev_buttons = r.buttons;
    if (!counts || r.rejected || !r.pos_m.allFinite()) continue;
    ++candidates;
    // the surface is at least last_d - moved away: rows that cannot beat the closest so far are skipped
    const double moved = (r.pos_m - last_p).norm();
    if (std::isfinite(moved) && last_d - moved >= closest_m) continue;
    const auto hit = nearest_surface_point(model, r.pos_m);
    if (!hit) continue;
    last_p = r.pos_m;
    last_d = hit->distance_m;
    closest_m = std::min(closest_m, last_d);
  }
  const std::string h = head;
  if (candidates == 0)
    return h + (scene.mode == InteractionMode::kTouch ? "the log holds no tool position"
                                                      : "the button is never pressed (pull grabs and cut cuts only while it is)");
  if (!std::isfinite(closest_m)) return h + "the model has no surface to touch";
  if (scene.mode == InteractionMode::kPull)
    return h + "the button is pressed " + mm(closest_m) + " from the surface at its closest (grab_radius_m is " +
           mm(scene.grab_radius_m) + ")";
  // within a leaf cell the tool did reach the surface: contact was refused, not missed
  if (closest_m <= 0.5 * model.leaf_cell_m)
    return h + "the tool comes within " + mm(closest_m) +
           " of the surface but never enters it from outside (contact starts where the tool crosses a face from its "
           "front, counter-clockwise side; closed parts are turned outward at load, an open shell keeps the side most "
           "of it faces: does it face away from the tool?)";
  return h + (scene.mode == InteractionMode::kCut ? "with the button held, the blade tip stays " : "the trajectory stays ") +
         mm(closest_m) + " from the surface at its closest";
}

std::string tool_inside_note(const FrameStats& stats) {
  if (stats.tool_inside_frames == 0 && stats.tool_inside_ticks + stats.proxy_inside_ticks == 0) return "";
  char buf[320];
  if (stats.tool_inside_frames == 0) {
    // only the every-tick check saw it: nearer the surface than the frames' proof reaches
    std::snprintf(buf, sizeof buf,
                  "the %s was inside the object from %.2f s, in %lld servo tick(s)%s: %s",
                  stats.tool_inside_ticks > 0 ? "tool" : "proxy", stats.through_first_t_s,
                  static_cast<long long>(stats.tool_inside_ticks + stats.proxy_inside_ticks),
                  stats.tool_inside_ticks > 0 && stats.proxy_inside_ticks > 0 ? " (tool free, or proxy held)" : "",
                  stats.tool_inside_ticks > 0 ? "the touch was lost (the tool went through the surface) or never began"
                                              : "the proxy crossed the surface it was held on");
    return buf;
  }
  std::snprintf(buf, sizeof buf,
                "the tool was inside the object without touching it from %.2f s, in %lld frames, at least %s under its "
                "rest surface: the touch was lost (the tool went through the surface) or never began",
                stats.tool_inside_first_t_s, static_cast<long long>(stats.tool_inside_frames),
                mm(stats.tool_inside_depth_m).c_str());
  return buf;
}

}  // namespace palpate
