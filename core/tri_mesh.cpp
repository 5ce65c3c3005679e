#include "core/tri_mesh.h"

#include "core/pair_key.h"

#include <algorithm>
#include <unordered_map>

namespace palpate {

void compute_vertex_normals(const std::vector<Vec3>& vertices_m,
                            const std::vector<std::array<int32_t, 3>>& triangles,
                            std::vector<Vec3>* normals) {
  normals->assign(vertices_m.size(), Vec3::Zero());
  // cross product length is twice the area: area weighting comes for free
  for (const auto& t : triangles) {
    const Vec3 n = (vertices_m[t[1]] - vertices_m[t[0]]).cross(vertices_m[t[2]] - vertices_m[t[0]]);
    for (int c = 0; c < 3; ++c) (*normals)[t[c]] += n;
  }
  for (Vec3& n : *normals) {
    const double len = n.norm();
    if (len > 0.0) n /= len;
  }
}

TriMesh subdivide_midpoint(const TriMesh& mesh) {
  TriMesh out;
  out.vertices_m = mesh.vertices_m;
  out.triangles.reserve(4 * mesh.triangles.size());
  std::unordered_map<uint64_t, int32_t> midpoint;  // edge (lo, hi) -> new vertex
  auto mid = [&](int32_t a, int32_t b) {
    auto [it, fresh] = midpoint.try_emplace(unordered_pair_key(a, b), static_cast<int32_t>(out.vertices_m.size()));
    if (fresh) out.vertices_m.push_back(0.5 * (mesh.vertices_m[a] + mesh.vertices_m[b]));
    return it->second;
  };
  for (const auto& t : mesh.triangles) {
    const int32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
    out.triangles.push_back({t[0], ab, ca});
    out.triangles.push_back({ab, t[1], bc});
    out.triangles.push_back({ca, bc, t[2]});
    out.triangles.push_back({ab, bc, ca});
  }
  return out;
}

}  // namespace palpate
