#include "render/renderer.h"

// The renderer's re-split: when the mesh's topology changes (a cut), the layered frame's moving part is split again
// and its local vertex arrays refilled, without redrawing the static layer.

#include <algorithm>
#include <cstring>

namespace palpate {
namespace {

// FNV-1a over the index data: detects a topology change (e.g. a cut) without keeping a copy.
uint64_t hash_triangles(const std::vector<std::array<int32_t, 3>>& triangles) {
  uint64_t h = 1469598103934665603ull;
  for (const auto& t : triangles) {
    for (int32_t i : t) h = (h ^ static_cast<uint32_t>(i)) * 1099511628211ull;
  }
  return h;
}

}  // namespace

void Renderer::fill_local_vertices() {
  const auto& local = layers_.local_vertices();
  local_positions_f_.resize(3 * local.size());
  if (style_ != RenderStyle::kWireframe) local_normals_f_.resize(3 * local.size());
  local_colors_.resize(colors_.empty() ? 0 : 4 * local.size());
  local_shadow_f_.resize(shadow_f_.empty() ? 0 : 3 * local.size());
  for (std::size_t i = 0; i < local.size(); ++i) {
    if (!colors_.empty())
      std::copy_n(colors_.begin() + static_cast<std::ptrdiff_t>(4 * local[i]), 4,
                  local_colors_.begin() + static_cast<std::ptrdiff_t>(4 * i));
    if (!shadow_f_.empty())
      std::copy_n(shadow_f_.begin() + static_cast<std::ptrdiff_t>(3 * local[i]), 3,
                  local_shadow_f_.begin() + static_cast<std::ptrdiff_t>(3 * i));
    const auto from = static_cast<std::ptrdiff_t>(3 * local[i]);
    const auto to = static_cast<std::ptrdiff_t>(3 * i);
    std::copy_n(positions_f_.begin() + from, 3, local_positions_f_.begin() + to);
    if (style_ != RenderStyle::kWireframe) std::copy_n(normals_f_.begin() + from, 3, local_normals_f_.begin() + to);
  }
}

bool Renderer::resplit(const FrameView& view) {
  const std::vector<Vec3>& vertices = *view.vertices_m;
  const auto& triangles = *view.triangles;
  // the static vertices keep the positions the layer was drawn with; the new ones move, and are written from the
  // view below with every affected vertex
  positions_f_.resize(3 * vertices.size(), 0.0f);
  if (style_ != RenderStyle::kWireframe) normals_f_.resize(3 * vertices.size(), 0.0f);
  if (!colors_.empty()) colors_.resize(4 * vertices.size(), 0);
  if (!shadow_f_.empty()) shadow_f_.resize(3 * vertices.size(), 0.0f);
  // a mesh grown inside the dynamic part (a cut) is split again there only, its indices checked there (the static
  // triangles are drawn from the layer); else the whole mesh, its indices checked first
  if (lines_drawn() || !layers_.grow(vertices.size(), triangles, *view.moving_vertices)) {
    const auto n_v = static_cast<int64_t>(vertices.size());
    for (int32_t v : *view.moving_vertices)
      if (v < 0 || v >= n_v) return false;
    for (const auto& t : triangles)
      if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= n_v || t[1] >= n_v || t[2] >= n_v) return false;
    if (lines_drawn()) update_edges(triangles);
    layers_.split(vertices.size(), triangles, edge_indices_, *view.moving_vertices);
  }
  fill_local_vertices();
  update_local_vertices(view);
  const auto& local = layers_.local_vertices();
  if (layer_culled_) {
    local_xy_.resize(2 * local.size());
    place(local_positions_f_.data(), local.size(), &local_xy_, &local_fill_cells_, &local_line_cells_);
  }
  layer_vertices_ = vertices.size();
  layer_triangles_ = triangles.size();
  layer_topology_ = view.topology_epoch;
  ++resplits_;
  return true;
}

bool Renderer::update_local_vertices(const FrameView& view) {
  // only the affected vertices (the first local ones) can differ from what the local arrays hold
  const std::vector<Vec3>& vertices = *view.vertices_m;
  const auto& affected = layers_.affected_vertices();
  bool changed = false;
  auto put = [&changed](float* to, double value) {
    const auto f = static_cast<float>(value);
    changed = changed || std::memcmp(to, &f, sizeof f) != 0;
    *to = f;
  };
  for (std::size_t i = 0; i < affected.size(); ++i)
    for (int c = 0; c < 3; ++c) put(&local_positions_f_[3 * i + c], vertices[affected[i]][c]);
  if (!local_colors_.empty()) {
    for (std::size_t i = 0; i < affected.size(); ++i) {
      const auto rgba = vertex_color(view, affected[i], vertices[affected[i]]);
      uint8_t* to = &local_colors_[4 * i];
      changed = changed || std::memcmp(to, rgba.data(), 4) != 0;
      std::copy(rgba.begin(), rgba.end(), to);
    }
  }
  if (!local_shadow_f_.empty())
    for (std::size_t i = 0; i < affected.size(); ++i) {
      const Vec3 f = shadow_point(view, vertices[affected[i]]);
      for (int c = 0; c < 3; ++c) local_shadow_f_[3 * i + c] = static_cast<float>(f[c]);
    }
  if (style_ == RenderStyle::kWireframe) return changed;
  const std::vector<Vec3>* normals = view.normals;
  if (normals != nullptr && normals->size() == vertices.size()) {
    for (std::size_t i = 0; i < affected.size(); ++i)
      for (int c = 0; c < 3; ++c) put(&local_normals_f_[3 * i + c], (*normals)[affected[i]][c]);
    return changed;
  }
  // no normals given: every triangle at an affected vertex is dynamic, and the dynamic triangles are in mesh
  // order, so summing their face normals gives compute_vertex_normals' result bit for bit
  const auto& local = layers_.local_vertices();
  const auto& tris = layers_.dynamic_triangles();
  local_normals_.assign(affected.size(), Vec3::Zero());
  for (std::size_t k = 0; k + 2 < tris.size(); k += 3) {
    const Vec3& a = vertices[local[tris[k]]];
    const Vec3 n = (vertices[local[tris[k + 1]]] - a).cross(vertices[local[tris[k + 2]]] - a);
    for (int c = 0; c < 3; ++c)
      if (tris[k + c] < affected.size()) local_normals_[tris[k + c]] += n;
  }
  for (std::size_t i = 0; i < affected.size(); ++i) {
    Vec3& n = local_normals_[i];
    const double len = n.norm();
    if (len > 0.0) n /= len;
    for (int c = 0; c < 3; ++c) put(&local_normals_f_[3 * i + c], n[c]);
  }
  return changed;
}

void Renderer::update_edges(const std::vector<std::array<int32_t, 3>>& triangles) {
  const uint64_t hash = hash_triangles(triangles);
  if (hash == edges_hash_ && triangles.size() == edges_triangles_ && !edge_indices_.empty()) return;
  edge_keys_.clear();
  for (const auto& t : triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<uint32_t>(t[k]), b = static_cast<uint32_t>(t[(k + 1) % 3]);
      edge_keys_.push_back(static_cast<uint64_t>(std::min(a, b)) << 32 | std::max(a, b));
    }
  }
  std::sort(edge_keys_.begin(), edge_keys_.end());
  edge_keys_.erase(std::unique(edge_keys_.begin(), edge_keys_.end()), edge_keys_.end());
  edge_indices_.clear();
  for (uint64_t key : edge_keys_) {
    edge_indices_.push_back(static_cast<uint32_t>(key >> 32));
    edge_indices_.push_back(static_cast<uint32_t>(key & 0xffffffffu));
  }
  edges_hash_ = hash;
  edges_triangles_ = triangles.size();
}

}  // namespace palpate
