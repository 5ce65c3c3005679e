// The frame stage's patch for the servo: the triangles near the tool and the god-object, nearest first when more are
// near than a patch holds, with what the patch covers and the corners it blends from (LocalModel).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "runtime/session/frame_stage.h"

namespace palpate {

void FrameStage::publish_patch() {
  LocalModel& m = local_model_->write_buffer();
  // triangles near the tool and the proxy, with a margin for the deformation since rest
  // (a sphere tool reaches its radius beyond its centre)
  const double margin = std::max(2.0 * model_.leaf_cell_m, scene_.grab_radius_m) + stats_.max_displacement_m +
                        (scene_.device.sphere_tool ? scene_.device.tool_radius_m : 0.0);
  // touch: what the servo's god-object can reach this frame (the patch is ordered by it and covers it): in contact,
  // the god-object, however deep the tool is pressed; free, the tool and where the servo last saw it outside
  const HapticSample& latest = feed_.latest();
  const bool touch = scene_.mode == InteractionMode::kTouch;
  Vec3 box_lo = latest.tool_pos_m.cwiseMin(latest.proxy_pos_m);
  Vec3 box_hi = latest.tool_pos_m.cwiseMax(latest.proxy_pos_m);
  Vec3 cover_lo = box_lo, cover_hi = box_hi;
  if (touch) {
    box_lo = box_lo.cwiseMin(latest.god_pos_m);
    box_hi = box_hi.cwiseMax(latest.god_pos_m);
    const bool held = latest.contact == ContactState::kTouch;
    cover_lo = held ? latest.god_pos_m : latest.tool_pos_m.cwiseMin(latest.god_pos_m);
    cover_hi = held ? latest.god_pos_m : latest.tool_pos_m.cwiseMax(latest.god_pos_m);
  }
  const Vec3 lo = box_lo - Vec3::Constant(margin);
  const Vec3 hi = box_hi + Vec3::Constant(margin);
  region_->patch_candidates(latest, vertices_m_, lo, hi, margin, &near_tris_);
  // keep the held triangle first, then the nearest ones
  const Vec3 tool = latest.tool_pos_m;
  const auto& tris = triangles();
  // nearest to the tool, or to the edge the region names (a blade: the triangles it crosses are always kept); in
  // touch, nearest to the box by the nearest any part of the triangle can be (a large face near the tool is kept)
  const Vec3 edge = region_->patch_edge(latest);
  auto dist = [&](int32_t t) {
    const auto& tr = tris[static_cast<std::size_t>(t)];
    const Vec3 c = (vertices_m_[tr[0]] + vertices_m_[tr[1]] + vertices_m_[tr[2]]) / 3.0;
    if (touch) {
      const double rad = std::sqrt(std::max({(vertices_m_[tr[0]] - c).squaredNorm(), (vertices_m_[tr[1]] - c).squaredNorm(),
                                             (vertices_m_[tr[2]] - c).squaredNorm()}));
      return std::max(0.0, (c - c.cwiseMax(cover_lo).cwiseMin(cover_hi)).norm() - rad);
    }
    const double u = edge.squaredNorm() > 0.0 ? std::clamp((c - tool).dot(edge) / edge.squaredNorm(), 0.0, 1.0) : 0.0;
    return (c - tool - u * edge).squaredNorm();
  };
  const int32_t held = latest.contact != ContactState::kFree ? latest.contact_tri : -1;
  m.truncated = near_tris_.size() > static_cast<std::size_t>(LocalModel::kMaxTriangles);
  // the patch is whole within margin of the cover box (less what the surface has moved since rest: candidates come
  // from the rest grid, in margin of a box holding it), or, truncated, up to the nearest triangle left out
  m.cover_lo_m = cover_lo;
  m.cover_hi_m = cover_hi;
  // (a whole patch holds every triangle within the margin, several leaf cells, of the box: more than a frame's way of
  // the god-object; only a patch cut short covers less than that)
  m.cover_radius_m = INFINITY;
  if (m.truncated) {
    // each distance once: nth_element moves the (distance, id) pairs exactly as it would move the ids compared by
    // distance, so the patch is the same triangles in the same order
    near_keys_.clear();
    for (int32_t t : near_tris_) near_keys_.emplace_back(dist(t), t);
    std::nth_element(near_keys_.begin(), near_keys_.begin() + LocalModel::kMaxTriangles - 1, near_keys_.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    near_tris_.resize(LocalModel::kMaxTriangles - 1);
    for (std::size_t i = 0; i < near_tris_.size(); ++i) near_tris_[i] = near_keys_[i].second;
    // the first triangle left out (the held one, kept apart, may be among them: it is in the patch all the same)
    if (touch) {
      double out_m = near_keys_[LocalModel::kMaxTriangles - 1].first;
      if (near_keys_[LocalModel::kMaxTriangles - 1].second == held)
        for (std::size_t i = LocalModel::kMaxTriangles; i < near_keys_.size(); ++i)
          if (near_keys_[i].second != held) out_m = std::min(out_m, near_keys_[i].first);
      m.cover_radius_m = std::min(margin - stats_.max_displacement_m, out_m);
    }
  }
  int n = 0;
  // the servo moves the surface from the last patch to this one over the frame, so the hand never feels the
  // frame's step (a cut renumbers triangles: its patches are not blended)
  const bool blend = scene_.mode != InteractionMode::kCut;
  // force shading: each corner's normal over the faces at it within the crease angle (a touch surface keeps the rest
  // mesh's triangles, whose adjacency the model holds)
  const bool crease = touch && scene_.device.force_shading_deg > 0.0 && tris.size() == model_.rest.triangles.size() &&
                      model_.adjacency.num_vertices() == vertices_m_.size();
  const double cos_crease = std::cos(scene_.device.force_shading_deg * std::numbers::pi / 180.0);
  auto put = [&](int32_t t) {
    const auto& tr = tris[static_cast<std::size_t>(t)];
    m.tri_ids[n] = t;
    m.part[n] = static_cast<std::size_t>(t) < model_.part_of.size() ? model_.part_of[static_cast<std::size_t>(t)] : 0;
    m.tri_m[n] = {vertices_m_[tr[0]], vertices_m_[tr[1]], vertices_m_[tr[2]]};
    m.normal[n] = {normals_[tr[0]], normals_[tr[1]], normals_[tr[2]]};
    for (int c = 0; c < 3; ++c)
      m.shade_normal[n][c] = crease ? crease_normal(vertices_m_, model_.rest.vertices_m, tris, model_.adjacency, t, c,
                                                    cos_crease)
                                    : Vec3::Zero();
    const auto it = blend ? published_.find(t) : published_.end();
    m.tri_from_m[n] = it != published_.end() ? it->second.corners : m.tri_m[n];
    m.shade_normal_from[n] = it != published_.end() ? it->second.normals : m.shade_normal[n];
    ++n;
  };
  if (held >= 0) put(held);
  for (int32_t t : near_tris_)
    if (t != held && n < LocalModel::kMaxTriangles) put(t);
  m.num_triangles = n;
  m.blend_s = blend ? scene_.rates.frame_period_s() : 0.0;
  published_.clear();
  for (int i = 0; i < n; ++i) published_[m.tri_ids[i]] = {m.tri_m[i], m.shade_normal[i]};
  m.frame = frame_index_;
  m.two_sided = touch && !model_.closed;
  m.controls_seq = controls_seq_;
  m.t_s = t_s_;
  lattice_contact_.fill_model(region_->lattice() ? &*region_->lattice() : nullptr, vertices_m_, feed_.frame(), &m);
  local_model_->publish();
}

}  // namespace palpate
