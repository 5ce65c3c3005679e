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
  static_tris_.clear();
  dynamic_ids_.clear();
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    const auto a = static_cast<uint32_t>(t[0]), b = static_cast<uint32_t>(t[1]), c = static_cast<uint32_t>(t[2]);
    if ((state_[a] | state_[b] | state_[c]) == kStatic) static_tris_.insert(static_tris_.end(), {a, b, c});
    else dynamic_ids_.push_back(static_cast<int32_t>(i));
  }
  n_triangles_ = triangles.size();
  local_ = affected_;
  number_dynamic(triangles);
  // lines are unlit: an edge changes only when one of its ends moves
  static_edges_.clear();
  dynamic_edges_.clear();
  had_edges_ = !edges.empty();
  for (std::size_t i = 0; i + 1 < edges.size(); i += 2) {
    const bool moves = state_[edges[i]] == kMoving || state_[edges[i + 1]] == kMoving;
    if (!moves) {
      static_edges_.insert(static_edges_.end(), {edges[i], edges[i + 1]});
      continue;
    }
    for (int k = 0; k < 2; ++k) {
      const uint32_t v = edges[i + static_cast<std::size_t>(k)];
      if (local_of_[v] < 0) {
        local_of_[v] = static_cast<int32_t>(local_.size());
        local_.push_back(static_cast<int32_t>(v));
      }
      dynamic_edges_.push_back(static_cast<uint32_t>(local_of_[v]));
    }
  }
}

void MeshLayers::number_dynamic(const std::vector<std::array<int32_t, 3>>& triangles) {
  // the local index of a mesh vertex, appending it the first time the dynamic part uses it
  dynamic_tris_.clear();
  for (int32_t id : dynamic_ids_)
    for (int32_t v : triangles[static_cast<std::size_t>(id)]) {
      if (local_of_[v] < 0) {
        local_of_[v] = static_cast<int32_t>(local_.size());
        local_.push_back(v);
      }
      dynamic_tris_.push_back(static_cast<uint32_t>(local_of_[v]));
    }
}

bool MeshLayers::grow(std::size_t n_vertices, const std::vector<std::array<int32_t, 3>>& triangles,
                      const std::vector<int32_t>& moving) {
  constexpr uint8_t kStatic = 0, kMoving = 2;
  const std::size_t n_old = state_.size();
  if (had_edges_ || n_vertices < n_old || triangles.size() < n_triangles_) return false;
  // the moving vertices: those that were, and every new one
  std::size_t fresh = 0;
  for (int32_t v : moving) {
    if (v < 0 || static_cast<std::size_t>(v) >= n_vertices) return false;
    if (static_cast<std::size_t>(v) >= n_old) ++fresh;
    else if (state_[static_cast<std::size_t>(v)] != kMoving) return false;
  }
  if (fresh != n_vertices - n_old) return false;
  // every corner of a rewritten or new triangle valid, and none static beside a moving one (its normal would change:
  // the static part would lose it)
  auto inside = [&](const std::array<int32_t, 3>& t) {
    bool moves = false, still = false;
    for (int32_t v : t) {
      if (v < 0 || static_cast<std::size_t>(v) >= n_vertices) return false;
      const uint8_t st = static_cast<std::size_t>(v) < n_old ? state_[static_cast<std::size_t>(v)] : kMoving;
      moves = moves || st == kMoving;
      still = still || st == kStatic;
    }
    return !(moves && still);
  };
  for (std::size_t i = n_triangles_; i < triangles.size(); ++i)
    if (!inside(triangles[i])) return false;
  for (int32_t id : dynamic_ids_)
    if (!inside(triangles[static_cast<std::size_t>(id)])) return false;
  state_.resize(n_vertices, kMoving);
  local_of_.resize(n_vertices, -1);
  // the affected vertices gain the new ones (the highest ids): the others the dynamic part uses are numbered anew
  for (std::size_t i = affected_.size(); i < local_.size(); ++i) local_of_[static_cast<std::size_t>(local_[i])] = -1;
  for (std::size_t v = n_old; v < n_vertices; ++v) {
    local_of_[v] = static_cast<int32_t>(affected_.size());
    affected_.push_back(static_cast<int32_t>(v));
  }
  local_ = affected_;
  for (std::size_t i = n_triangles_; i < triangles.size(); ++i) dynamic_ids_.push_back(static_cast<int32_t>(i));
  n_triangles_ = triangles.size();
  number_dynamic(triangles);
  return true;
}

}  // namespace palpate
