#pragma once
// Hand-made servo samples for frame-stage tests: a tool pressed into the top face of a box mesh.

#include <cmath>
#include <cstdint>

#include "core/tri_mesh.h"
#include "haptics/servo/haptic_sample.h"

namespace palpate::test {

/// A 6 cm box of 12 x 12 subdivided faces on a fixed floor, a one-cell lattice region at level 4 with raw spring
/// keys, touch mode: the frame-stage tests press its top face (z = 0.03 m) with pressed_sample().
inline constexpr const char* kPressedBoxScene = R"({
  "mesh": {"box_m": [0.06, 0.06, 0.06], "box_subdivisions": 12, "size_m": 0.06},
  "grid": {"levels": 4},
  "lattice": {"level": 4, "radius_cells": 1, "node_mass_kg": 0.003,
              "stiffness_N_per_m": {"structural": 60, "shear": 30, "bend": 15},
              "damping_Ns_per_m": 0.06, "fix_floor": true},
  "interaction": {"mode": "touch"},
  "trajectory": [{"t_s": 0.0, "pos_m": [0.0, 0.0, 0.05]}],
  "duration_s": 2.0
})";

/// The top-face triangle (centroid z at the mesh's top, within 0.1 mm of z = 0.03 m) whose centroid is nearest
/// (x, y); its centroid in *centroid. -1 when there is none.
inline int32_t top_triangle_near(const TriMesh& mesh, double x, double y, Vec3* centroid) {
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

/// The servo's sample at `tick` (1 kHz) of a tool held 2 mm into triangle `tri` at its centroid `contact_m`,
/// touching with 0.6 N straight down.
inline HapticSample pressed_sample(int64_t tick, int32_t tri, const Vec3& contact_m) {
  HapticSample s;
  s.tick = tick;
  s.t_s = static_cast<double>(tick) * 1e-3;
  s.tool_pos_m = contact_m - Vec3(0, 0, 0.002);
  s.proxy_pos_m = contact_m;
  s.contact = ContactState::kTouch;
  s.contact_tri = tri;
  s.contact_bary = Vec3::Constant(1.0 / 3.0);
  s.force_N = Vec3(0, 0, 0.6);
  return s;
}

}  // namespace palpate::test
