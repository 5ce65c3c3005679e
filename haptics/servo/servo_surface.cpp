// The servo's surface between sim frames: each corner moves from where the hand last felt it to the new frame's
// position over the frame, the contact model's force and compliance with it. Part of the servo (haptics/servo/servo.h).
// Thread: servo.
#include <algorithm>
#include <cstdint>

#include "haptics/servo/servo.h"

namespace palpate {

const LocalModel& Servo::surface_at(const LocalModel& src, double t_s) noexcept {
  surface_moved_ = src.frame != seen_frame_;
  seen_frame_ = src.frame;
  if (!(src.blend_s > 0.0) || !params_.surface_blend) return src;
  const double period_s = rates_.servo_period_s();
  if (src.frame != surface_.frame) {
    // the contact model's force and compliance move from the last frame's to this one's with the corners
    const bool had = surface_.has_contact_model && src.has_contact_model;
    from_f0_N_ = had ? surface_.contact_f0_N : src.contact_f0_N;
    from_compliance_m_per_N_ = had ? surface_.compliance_m_per_N : src.compliance_m_per_N;
    // the corners start where the hand last felt them: a frame that comes before the last one's way is done (a
    // realtime sim frame early after a late one) starts from the servo's corners, not the last frame's (from there a
    // held grab jumped the rest of the way at once: 0.7-1.1 mm, steps of 0.2 N on a shaken spring bunny)
    const bool midway = surface_alpha_ >= 0.0 && surface_alpha_ < 1.0 && surface_.num_triangles > 0;
    if (midway) {
      id_key_.fill(0);
      for (int i = 0; i < surface_.num_triangles; ++i) {
        const uint32_t key = static_cast<uint32_t>(surface_.tri_ids[i]) + 1u;
        for (uint32_t h = key * 2654435761u % kIdTable;; h = (h + 1) % kIdTable)
          if (id_key_[h] == 0) {
            id_key_[h] = static_cast<int32_t>(key);
            id_slot_[h] = static_cast<int16_t>(i);
            break;
          }
      }
    }
    for (int i = 0; i < src.num_triangles; ++i) {
      from_corners_[i] = src.tri_from_m[i];
      if (!midway) continue;
      const uint32_t key = static_cast<uint32_t>(src.tri_ids[i]) + 1u;
      for (uint32_t h = key * 2654435761u % kIdTable; id_key_[h] != 0; h = (h + 1) % kIdTable)
        if (id_key_[h] == static_cast<int32_t>(key)) {
          from_corners_[i] = surface_.tri_m[id_slot_[h]];
          break;
        }
    }
    surface_ = src;
    surface_start_s_ = t_s;
    surface_alpha_ = -1.0;
  }
  // the first tick moves a tick's share, the last tick before the next frame arrives at the frame's corners
  const double span_s = std::max(period_s, src.blend_s - period_s);
  const double a = std::clamp((t_s - surface_start_s_ + period_s) / span_s, 0.0, 1.0);
  if (a != surface_alpha_) {
    const bool shading = shade_full_cos_ < 1.0;
    for (int i = 0; i < src.num_triangles; ++i)
      for (int c = 0; c < 3; ++c) {
        surface_.tri_m[i][c] = from_corners_[i][c] + a * (src.tri_m[i][c] - from_corners_[i][c]);
        if (shading)
          surface_.shade_normal[i][c] =
              src.shade_normal_from[i][c] + a * (src.shade_normal[i][c] - src.shade_normal_from[i][c]);
      }
    surface_moved_ = true;
    surface_.contact_f0_N = from_f0_N_ + a * (src.contact_f0_N - from_f0_N_);
    surface_.compliance_m_per_N = from_compliance_m_per_N_ + a * (src.compliance_m_per_N - from_compliance_m_per_N_);
    surface_alpha_ = a;
  }
  return surface_;
}

}  // namespace palpate
