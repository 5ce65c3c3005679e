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
  local_.clear();
  local_of_.assign(n_vertices, -1);
  for (std::size_t v = 0; v < n_vertices; ++v) {
    if (state_[v] == kStatic) continue;
    local_of_[v] = static_cast<int32_t>(affected_.size());
    affected_.push_back(static_cast<int32_t>(v));
  }
  local_ = affected_;
  // the local index of a mesh vertex, appending it the first time the dynamic part uses it
  auto local = [&](uint32_t v) {
    if (local_of_[v] < 0) {
      local_of_[v] = static_cast<int32_t>(local_.size());
      local_.push_back(static_cast<int32_t>(v));
    }
    return static_cast<uint32_t>(local_of_[v]);
  };

  static_tris_.clear();
  dynamic_tris_.clear();
  for (const auto& t : triangles) {
    const auto a = static_cast<uint32_t>(t[0]), b = static_cast<uint32_t>(t[1]), c = static_cast<uint32_t>(t[2]);
    if ((state_[a] | state_[b] | state_[c]) == kStatic) static_tris_.insert(static_tris_.end(), {a, b, c});
    else dynamic_tris_.insert(dynamic_tris_.end(), {local(a), local(b), local(c)});
  }
  // lines are unlit: an edge changes only when one of its ends moves
  static_edges_.clear();
  dynamic_edges_.clear();
  for (std::size_t i = 0; i + 1 < edges.size(); i += 2) {
    const bool moves = state_[edges[i]] == kMoving || state_[edges[i + 1]] == kMoving;
    if (moves) dynamic_edges_.insert(dynamic_edges_.end(), {local(edges[i]), local(edges[i + 1])});
    else static_edges_.insert(static_edges_.end(), {edges[i], edges[i + 1]});
  }
}

}  // namespace palpate
