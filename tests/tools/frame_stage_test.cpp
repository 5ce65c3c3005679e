// The frame stage driven by hand-made servo samples: a contact sliding across a box moves the region several
// times, and after every frame the normals it keeps (recomputed only where the region reaches) equal a
// recomputation of the whole mesh bit for bit.
#include "tools/session/frame_stage.h"

#include <gtest/gtest.h>

#include "core/tri_mesh.h"

namespace palpate {
namespace {

constexpr const char* kBox = R"({
  "mesh": {"box_m": [0.06, 0.06, 0.06], "box_subdivisions": 12, "size_m": 0.06},
  "grid": {"levels": 4},
  "lattice": {"level": 4, "radius_cells": 1, "node_mass_kg": 0.003,
              "stiffness_N_per_m": {"structural": 60, "shear": 30, "bend": 15},
              "damping_Ns_per_m": 0.06, "fix_floor": true},
  "interaction": {"mode": "touch"},
  "trajectory": [{"t_s": 0.0, "pos_m": [0.0, 0.0, 0.05]}],
  "duration_s": 2.0
})";

// The top-face triangle whose centroid is nearest (x, y).
int32_t top_triangle_near(const TriMesh& mesh, double x, double y, Vec3* centroid) {
  int32_t best = -1;
  double best_d = 1e9;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tr = mesh.triangles[t];
    const Vec3 c = (mesh.vertices_m[tr[0]] + mesh.vertices_m[tr[1]] + mesh.vertices_m[tr[2]]) / 3.0;
    if (c.z() < 0.0299) continue;
    const double d = std::hypot(c.x() - x, c.y() - y);
    if (d < best_d) best_d = d, best = static_cast<int32_t>(t), *centroid = c;
  }
  return best;
}

TEST(FrameStage, NormalsKeptOnlyWhereTheRegionReachesEqualTheWholeMeshs) {
  const Scene scene = parse_scene(kBox, "box.json").value();
  const Model model = load_model(scene).value();
  SpscQueue<HapticSample> samples(4096);
  TripleBuffer<LocalModel> local;
  FrameStage stage(scene, model, &samples, &local, nullptr, nullptr, nullptr);
  int64_t tick = 0, mismatched_frames = 0;
  for (int f = 0; f < 90; ++f) {
    // pressed 0.6 N into the top, sliding from x = -2 cm to +2 cm over the first 60 frames, then released
    const double x = -0.02 + 0.04 * std::min(f, 60) / 60.0;
    Vec3 c = Vec3::Zero();
    const int32_t tri = top_triangle_near(model.rest, x, 0.0, &c);
    ASSERT_GE(tri, 0);
    for (int k = 0; k < 16; ++k) {
      HapticSample s;
      s.tick = tick++;
      s.t_s = s.tick * 1e-3;
      s.tool_pos_m = c - Vec3(0, 0, 0.002);
      s.proxy_pos_m = c;
      if (f < 60) {
        s.contact = ContactState::kTouch;
        s.contact_tri = tri;
        s.contact_bary = Vec3::Constant(1.0 / 3.0);
        s.force_N = Vec3(0, 0, 0.6);
      }
      ASSERT_TRUE(samples.try_push(s));
    }
    stage.frame(f, f / 60.0, true);
    std::vector<Vec3> full;
    compute_vertex_normals(stage.vertices_m(), stage.triangles(), &full);
    ASSERT_EQ(full.size(), stage.normals().size());
    bool same = true;
    for (std::size_t v = 0; v < full.size(); ++v) same = same && (full[v].array() == stage.normals()[v].array()).all();
    mismatched_frames += same ? 0 : 1;
  }
  EXPECT_EQ(mismatched_frames, 0);
  EXPECT_GE(stage.stats().region_moves, 2);
  EXPECT_GT(stage.stats().max_displacement_m, 1e-4);
}

}  // namespace
}  // namespace palpate
