#pragma once
/// LocalModel: the sim's latest snapshot of the deformed surface near the tool, read by the servo.

#include <array>
#include <cmath>
#include <cstdint>

#include "core/types.h"

namespace palpate {

/// A fixed-capacity patch of deformed triangles. Plain data, copied through TripleBuffer (no allocation).
struct LocalModel {
  static constexpr int kMaxTriangles = 512;
  int64_t frame = -1;                                     ///< sim frame that produced it (-1 = none yet)
  int64_t controls_seq = 0;                               ///< the controls (Controls::seq) its session runs under: the
                                                          ///< servo feels no patch of another
  double t_s = 0.0;                                       ///< scene time of that frame
  int num_triangles = 0;                                  ///< triangles in use
  bool truncated = false;                                 ///< more triangles were near than fit
  std::array<int32_t, kMaxTriangles> tri_ids{};           ///< mesh triangle ids
  std::array<std::array<Vec3, 3>, kMaxTriangles> tri_m{}; ///< deformed corner positions
  std::array<std::array<Vec3, 3>, kMaxTriangles> normal{};///< unit vertex normals at the corners
  /// touch with force shading: each corner's normal over the faces that meet it at less than the crease angle in
  /// the rest shape (core/vertex_triangles.h, crease_normal), the normal the force follows; zero: no shading
  std::array<std::array<Vec3, 3>, kMaxTriangles> shade_normal{};
  /// the same corners as the servo last saw them (the frame before, or tri_m for a triangle new to the patch)
  std::array<std::array<Vec3, 3>, kMaxTriangles> tri_from_m{};
  /// shade_normal as the servo last saw it (blended with the corners)
  std::array<std::array<Vec3, 3>, kMaxTriangles> shade_normal_from{};
  double blend_s = 0.0;  ///< > 0: the servo moves each corner from tri_from_m to tri_m over this long from t_s
  /// touch: the surface is not closed (an open sheet, a cup, a scan with holes): it has no inside, and either side of
  /// a face can be touched
  bool two_sided = false;
  /// two_sided: each triangle's part (Model::part_of): a touch from the back of a face holds to that side of its part
  std::array<int32_t, kMaxTriangles> part{};

  // what the patch covers (touch): every triangle of the surface that comes within cover_radius_m of the box
  // [cover_lo_m, cover_hi_m] is in it; beyond, the servo knows nothing of the surface, so a free tool's path there is
  // judged only once a patch covers it (a tool that went through a face the patch left out would be inside, free).
  // +inf: no bound
  Vec3 cover_lo_m = Vec3::Zero();  ///< the box's low corner (world, m)
  Vec3 cover_hi_m = Vec3::Zero();  ///< its high corner
  double cover_radius_m = INFINITY;///< the distance from the box within which the patch is whole, m

  // the object's response at the contact between frames (multirate force), valid when has_contact_model:
  // the contact point moves by v0 (t - t_s) + C (F_obj - f0) for a force F_obj pushed on the object
  bool has_contact_model = false;
  Vec3 contact_p0_m = Vec3::Zero();       ///< contact point at the frame
  Vec3 contact_centre_m = Vec3::Zero();   ///< the god-object at the frame, before prediction (a sphere: its centre)
  Vec3 contact_v0_m_per_s = Vec3::Zero(); ///< its velocity at the frame
  Vec3 contact_f0_N = Vec3::Zero();       ///< force on the object during the frame's step
  Mat3 compliance_m_per_N = Mat3::Zero(); ///< C, static compliance at the contact (3 x 3, symmetric)
  double model_radius_m = 0.0;            ///< the model holds within this distance of p0 (a point tool's proxy) or
                                          ///< of contact_centre_m (a sphere tool's centre)
};

/// The patch src with the faces of part `part` turned over (corners 1 and 2 swapped, normals reversed), into *out: a
/// part touched from the back of its faces is then touched from their front, and other parts are as they were. A
/// turned corner's barycentric weights (b0, b1, b2) in src are (b0, b2, b1) in *out. Copies only the triangles in use.
/// Thread: any (no allocation).
inline void turn_over(const LocalModel& src, int32_t part, LocalModel* out) noexcept {
  out->frame = src.frame;
  out->controls_seq = src.controls_seq;
  out->t_s = src.t_s;
  out->num_triangles = src.num_triangles;
  out->truncated = src.truncated;
  out->blend_s = src.blend_s;
  out->two_sided = src.two_sided;
  out->cover_lo_m = src.cover_lo_m;
  out->cover_hi_m = src.cover_hi_m;
  out->cover_radius_m = src.cover_radius_m;
  out->has_contact_model = src.has_contact_model;
  out->contact_p0_m = src.contact_p0_m;
  out->contact_centre_m = src.contact_centre_m;
  out->contact_v0_m_per_s = src.contact_v0_m_per_s;
  out->contact_f0_N = src.contact_f0_N;
  out->compliance_m_per_N = src.compliance_m_per_N;
  out->model_radius_m = src.model_radius_m;
  for (int i = 0; i < src.num_triangles; ++i) {
    const bool turn = src.part[i] == part;
    const auto swap = [turn](const std::array<Vec3, 3>& c) {
      return turn ? std::array<Vec3, 3>{c[0], c[2], c[1]} : c;
    };
    const auto reverse = [turn](const std::array<Vec3, 3>& c) {
      return turn ? std::array<Vec3, 3>{-c[0], -c[2], -c[1]} : c;
    };
    out->tri_ids[i] = src.tri_ids[i];
    out->part[i] = src.part[i];
    out->tri_m[i] = swap(src.tri_m[i]);
    out->tri_from_m[i] = swap(src.tri_from_m[i]);
    out->normal[i] = reverse(src.normal[i]);
    out->shade_normal[i] = reverse(src.shade_normal[i]);
    out->shade_normal_from[i] = reverse(src.shade_normal_from[i]);
  }
}

}  // namespace palpate
