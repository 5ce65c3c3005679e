#pragma once
/// MeshDeformer: moves bound mesh vertices with their lattice cell by trilinear interpolation of its 8 nodes.

#include <cstdint>
#include <vector>

#include "core/binding.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// Trilinear weights of the 8 corners (corner = dx + 2dy + 4dz) at local coordinates p in [0,1]^3.
std::array<double, 8> trilinear_weights(const Vec3& p);

/// Deforms the vertices of the lattice's cells; vertices elsewhere keep their rest position and cost nothing.
/// Copyable; rebuild (attach) when the lattice's cells change.
class MeshDeformer {
 public:
  /// Indexes which vertices fall in which region cell. bindings are per vertex at lat.level.
  void attach(const Lattice& lat, const std::vector<VertexBinding>& bindings);
  /// Writes deformed positions of the region's vertices into *vertices_m (others untouched):
  /// v = v_rest + sum_c w_c (x_c - rest_c), which is trilinear interpolation of the deformed nodes
  /// and reproduces the rest position bit-exactly when the cell is undeformed.
  void deform(const Lattice& lat, const std::vector<VertexBinding>& bindings, const std::vector<Vec3>& rest_vertices_m,
              std::vector<Vec3>* vertices_m) const;
  /// Writes a value per node (n_nodes), interpolated as positions are, at each of the region's vertices into
  /// *vertex_values (others untouched).
  void interpolate(const Lattice& lat, const std::vector<VertexBinding>& bindings,
                   const std::vector<Vec3>& rest_vertices_m, const std::vector<double>& node_values,
                   std::vector<float>* vertex_values) const;
  /// Number of vertices that follow the lattice.
  std::size_t num_bound_vertices() const { return vertex_ids_.size(); }
  /// The vertex ids that follow the lattice, grouped by region cell.
  const std::vector<int32_t>& vertex_ids() const { return vertex_ids_; }

 private:
  std::vector<int32_t> vertex_ids_;  // vertices inside region cells (n_b)
  std::vector<int32_t> vertex_slot_; // region slot of each of them (n_b)
};

/// The paper's eq. (9) for comparison: v = P * R + b with R the cell's current axis extents from its base node.
Vec3 deform_eq9(const Lattice& lat, int32_t slot, const Vec3& local);

}  // namespace palpate
