#include "render/mesh_layers.h"

namespace palpate {

void MeshLayers::split(std::size_t n_vertices, const std::vector<std::array<int32_t, 3>>& triangles,
                       const std::vector<uint32_t>& edges, const std::vector<int32_t>& moving) {
  constexpr uint8_t kStatic = 0, kShaded = 1, kMoving = 2;
  state_.assign(n_vertices, kStatic);
  for (int32_t v : moving) state_[static_cast<std::size_t>(v)] = kMoving;
  // a triangle with a moving vertex changes the normals of all three of its vertices
  for (const auto& t : triangles) {
    if (state_[t[0]] != kMoving && state_[t[1]] != kMoving && state_[t[2]] != kMoving) continue;
    for (int32_t v : t)
      if (state_[v] == kStatic) state_[v] = kShaded;
  }
  affected_.clear();
  for (std::size_t v = 0; v < n_vertices; ++v)
    if (state_[v] != kStatic) affected_.push_back(static_cast<int32_t>(v));

  static_tris_.clear();
  dynamic_tris_.clear();
  for (const auto& t : triangles) {
    auto* out = (state_[t[0]] | state_[t[1]] | state_[t[2]]) != kStatic ? &dynamic_tris_ : &static_tris_;
    out->insert(out->end(), {static_cast<uint32_t>(t[0]), static_cast<uint32_t>(t[1]), static_cast<uint32_t>(t[2])});
  }
  // lines are unlit: an edge changes only when one of its ends moves
  static_edges_.clear();
  dynamic_edges_.clear();
  for (std::size_t i = 0; i + 1 < edges.size(); i += 2) {
    const bool moves = state_[edges[i]] == kMoving || state_[edges[i + 1]] == kMoving;
    auto* out = moves ? &dynamic_edges_ : &static_edges_;
    out->insert(out->end(), {edges[i], edges[i + 1]});
  }
}

}  // namespace palpate
