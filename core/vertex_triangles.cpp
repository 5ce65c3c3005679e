#include "core/vertex_triangles.h"

#include <algorithm>

namespace palpate {

VertexTriangles VertexTriangles::build(std::size_t n_vertices, const std::vector<std::array<int32_t, 3>>& triangles) {
  VertexTriangles a;
  a.offsets.assign(n_vertices + 1, 0);
  for (const auto& t : triangles)
    for (int32_t v : t) ++a.offsets[static_cast<std::size_t>(v) + 1];
  for (std::size_t i = 0; i < n_vertices; ++i) a.offsets[i + 1] += a.offsets[i];
  a.triangles.resize(3 * triangles.size());
  // fill rows in triangle order, so each row is ascending
  std::vector<int32_t> next(a.offsets.begin(), a.offsets.end() - 1);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int32_t v : triangles[t]) a.triangles[static_cast<std::size_t>(next[v]++)] = static_cast<int32_t>(t);
  return a;
}

Vec3 vertex_normal(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                   const int32_t* ids, std::size_t count) {
  // the same face normal expression and summation order as compute_vertex_normals
  Vec3 sum = Vec3::Zero();
  for (std::size_t k = 0; k < count; ++k) {
    const auto& t = triangles[static_cast<std::size_t>(ids[k])];
    sum += (vertices_m[t[1]] - vertices_m[t[0]]).cross(vertices_m[t[2]] - vertices_m[t[0]]);
  }
  const double len = sum.norm();
  if (len > 0.0) sum /= len;
  return sum;
}

Vec3 crease_normal(const std::vector<Vec3>& vertices_m, const std::vector<Vec3>& rest_m,
                   const std::vector<std::array<int32_t, 3>>& triangles, const VertexTriangles& adjacency, int32_t tri,
                   int corner, double cos_crease) {
  auto face = [&](const std::vector<Vec3>& x, int32_t t) {
    const auto& c = triangles[static_cast<std::size_t>(t)];
    return Vec3((x[c[1]] - x[c[0]]).cross(x[c[2]] - x[c[0]]));
  };
  const Vec3 own = face(rest_m, tri);
  const double own_len = own.norm();
  const int32_t v = triangles[static_cast<std::size_t>(tri)][static_cast<std::size_t>(corner)];
  Vec3 sum = Vec3::Zero();
  for (int32_t k = adjacency.offsets[v]; k < adjacency.offsets[v + 1]; ++k) {
    const int32_t t = adjacency.triangles[static_cast<std::size_t>(k)];
    // which faces are one smooth surface is the rest shape's (a dent pressed into it is no crease);
    // |f| |own| cos(turn) >= cos_crease |f| |own|; the triangle itself counts even when degenerate
    const Vec3 f = face(rest_m, t);
    if (t == tri || f.dot(own) >= cos_crease * f.norm() * own_len) sum += face(vertices_m, t);
  }
  const double len = sum.norm();
  if (len > 0.0) sum /= len;
  return sum;
}

void update_vertex_normals(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                           const VertexTriangles& adjacency, const std::vector<int32_t>& vertex_ids,
                           std::vector<Vec3>* normals) {
  for (int32_t v : vertex_ids) {
    const int32_t begin = adjacency.offsets[v];
    (*normals)[v] = vertex_normal(vertices_m, triangles, adjacency.triangles.data() + begin,
                                  static_cast<std::size_t>(adjacency.offsets[v + 1] - begin));
  }
}

void VertexNormalPatch::attach(const VertexTriangles& adjacency, const std::vector<int32_t>& vertex_ids) {
  vertex_ids_ = vertex_ids;
  offsets_.assign(1, 0);
  triangle_ids_.clear();
  for (int32_t v : vertex_ids) {
    triangle_ids_.insert(triangle_ids_.end(), adjacency.triangles.begin() + adjacency.offsets[v],
                         adjacency.triangles.begin() + adjacency.offsets[v + 1]);
    offsets_.push_back(static_cast<int32_t>(triangle_ids_.size()));
  }
  // the rows, as slots into the sorted distinct triangles
  face_slots_ = triangle_ids_;
  std::sort(triangle_ids_.begin(), triangle_ids_.end());
  triangle_ids_.erase(std::unique(triangle_ids_.begin(), triangle_ids_.end()), triangle_ids_.end());
  for (int32_t& t : face_slots_)
    t = static_cast<int32_t>(std::lower_bound(triangle_ids_.begin(), triangle_ids_.end(), t) - triangle_ids_.begin());
  faces_.resize(triangle_ids_.size());
}

void VertexNormalPatch::update(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                               std::vector<Vec3>* normals) {
  // the same face normal expression as compute_vertex_normals, once per triangle
  for (std::size_t f = 0; f < triangle_ids_.size(); ++f) {
    const auto& t = triangles[static_cast<std::size_t>(triangle_ids_[f])];
    faces_[f] = (vertices_m[t[1]] - vertices_m[t[0]]).cross(vertices_m[t[2]] - vertices_m[t[0]]);
  }
  // summed per vertex in its adjacency row's order (ascending triangles): compute_vertex_normals' order
  for (std::size_t i = 0; i < vertex_ids_.size(); ++i) {
    Vec3 sum = Vec3::Zero();
    for (int32_t k = offsets_[i]; k < offsets_[i + 1]; ++k) sum += faces_[static_cast<std::size_t>(face_slots_[k])];
    const double len = sum.norm();
    if (len > 0.0) sum /= len;
    (*normals)[vertex_ids_[i]] = sum;
  }
}

void normal_dependents(const std::vector<std::array<int32_t, 3>>& triangles, const VertexTriangles& adjacency,
                       const std::vector<int32_t>& moving, std::vector<uint8_t>* mark, std::vector<int32_t>* out) {
  out->clear();
  if (mark->size() < adjacency.num_vertices()) mark->resize(adjacency.num_vertices(), 0);
  for (int32_t v : moving) {
    for (int32_t k = adjacency.offsets[v]; k < adjacency.offsets[v + 1]; ++k) {
      for (int32_t u : triangles[static_cast<std::size_t>(adjacency.triangles[k])]) {
        if ((*mark)[u] == 0) {
          (*mark)[u] = 1;
          out->push_back(u);
        }
      }
    }
  }
  for (int32_t u : *out) (*mark)[u] = 0;
  std::sort(out->begin(), out->end());
}

}  // namespace palpate
