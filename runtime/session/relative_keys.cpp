#include "runtime/session/relative_keys.h"

#include <cstdio>
#include <string>

#include "runtime/session/surface_queries.h"

namespace palpate {
namespace {

std::string mm3(const Vec3& p_m) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.1f, %.1f, %.1f] mm", 1e3 * p_m.x(), 1e3 * p_m.y(), 1e3 * p_m.z());
  return buf;
}

}  // namespace

Status resolve_relative_keys(const Model& model, Scene* scene) {
  const Aabb box = Aabb::of(model.rest.vertices_m);
  // far enough to leave the workspace: every surface point the ray can reach lies within it
  const double reach_m = 2.0 * (box.extent().norm() + (box.center()).norm()) + 1.0;
  for (std::size_t i = 0; i < scene->trajectory.size(); ++i) {
    Keyframe& k = scene->trajectory[i];
    if (!needs_model(k)) continue;
    const std::string who = "scene '" + scene->path + "': trajectory[" + std::to_string(i) + "]: ";
    if (k.pos_rel) k.pos_m = box.min_m + k.pos_rel->cwiseProduct(box.extent());
    // resolved: from here on an absolute key like any other
    k.pos_rel.reset();
    if (!k.surface) continue;
    k.surface = false;
    // the approach: from the previous key through this one, or from this key toward the model's centre
    Vec3 from = i > 0 ? scene->trajectory[i - 1].pos_m : k.pos_m;
    Vec3 dir = k.pos_m - from;
    if (dir.norm() < 1e-9) {
      from = k.pos_m;
      dir = box.center() - k.pos_m;
    }
    if (dir.norm() < 1e-9)
      return make_error(who, "surface: no approach direction (the key is at the previous key and at the model's centre)");
    dir.normalize();
    const auto hit = first_ray_hit(model, from, dir, reach_m, true);
    if (!hit)
      return make_error(who, "surface: the approach from ", mm3(from), " toward ", mm3(k.pos_m),
                        " misses the model (box ", mm3(box.min_m), " .. ", mm3(box.max_m), ")");
    k.pos_m = hit->point_m + k.depth_m * dir;
  }
  return Ok{};
}

}  // namespace palpate
