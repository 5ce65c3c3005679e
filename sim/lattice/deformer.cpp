#include "sim/lattice/deformer.h"

namespace palpate {

std::array<double, 8> trilinear_weights(const Vec3& p) {
  std::array<double, 8> w{};
  for (int c = 0; c < 8; ++c) {
    const double wx = (c & 1) ? p.x() : 1.0 - p.x();
    const double wy = (c & 2) ? p.y() : 1.0 - p.y();
    const double wz = (c & 4) ? p.z() : 1.0 - p.z();
    w[c] = wx * wy * wz;
  }
  return w;
}

void MeshDeformer::attach(const Lattice& lat, const std::vector<VertexBinding>& bindings) {
  vertex_ids_.clear();
  vertex_slot_.clear();
  for (std::size_t v = 0; v < bindings.size(); ++v) {
    const int32_t slot = lat.slot_of_cell[bindings[v].cell];
    if (slot < 0) continue;
    vertex_ids_.push_back(static_cast<int32_t>(v));
    vertex_slot_.push_back(slot);
  }
}

void MeshDeformer::deform(const Lattice& lat, const std::vector<VertexBinding>& bindings,
                          const std::vector<Vec3>& rest_vertices_m, std::vector<Vec3>* vertices_m) const {
  for (std::size_t i = 0; i < vertex_ids_.size(); ++i) {
    const int32_t v = vertex_ids_[i];
    const auto& nodes = lat.cell_nodes[vertex_slot_[i]];
    // a refined lattice's coarse cell spans several cells of the bindings' level: local coordinates in it
    const auto w = trilinear_weights(lat.cell_span.empty() ? bindings[v].local
                                                           : lat.local_in_cell(static_cast<std::size_t>(vertex_slot_[i]),
                                                                               rest_vertices_m[v]));
    Vec3 d = Vec3::Zero();
    for (int c = 0; c < 8; ++c) d += w[c] * (lat.x_m[nodes[c]] - lat.rest_m[nodes[c]]);
    (*vertices_m)[v] = rest_vertices_m[v] + d;
  }
}

void MeshDeformer::interpolate(const Lattice& lat, const std::vector<VertexBinding>& bindings,
                               const std::vector<Vec3>& rest_vertices_m, const std::vector<double>& node_values,
                               std::vector<float>* vertex_values) const {
  for (std::size_t i = 0; i < vertex_ids_.size(); ++i) {
    const int32_t v = vertex_ids_[i];
    const auto& nodes = lat.cell_nodes[vertex_slot_[i]];
    const auto w = trilinear_weights(lat.cell_span.empty() ? bindings[v].local
                                                           : lat.local_in_cell(static_cast<std::size_t>(vertex_slot_[i]),
                                                                               rest_vertices_m[v]));
    double value = 0.0;
    for (int c = 0; c < 8; ++c) value += w[c] * node_values[static_cast<std::size_t>(nodes[c])];
    (*vertex_values)[static_cast<std::size_t>(v)] = static_cast<float>(value);
  }
}

Vec3 deform_eq9(const Lattice& lat, int32_t slot, const Vec3& local) {
  const auto& n = lat.cell_nodes[slot];
  const Vec3 b = lat.x_m[n[0]];
  // R_i: distance from the base node to its neighbour along axis i (the paper's scale factors)
  const Vec3 r((lat.x_m[n[1]] - b).norm(), (lat.x_m[n[2]] - b).norm(), (lat.x_m[n[4]] - b).norm());
  return b + local.cwiseProduct(r);
}

}  // namespace palpate
