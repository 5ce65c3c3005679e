#include "core/tri_mesh.h"

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

}  // namespace palpate
