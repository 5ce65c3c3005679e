#pragma once
// A block held at its floor, its lattice over the whole of it and its surface mesh bound to the lattice: what the
// contact load tests press on.

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/binding.h"
#include "sim/contact/contact_load.h"
#include "sim/lattice/lattice.h"
#include "sim_test_util.h"

namespace palpate::test {

constexpr double kContactBlockSide_m = 0.08;  // from -0.04 to 0.04

/// The block at lattice level `level` (level 3: cells of 2 cm), its faces cut in subdivisions^2 quads (8: 1 cm).
/// Not copyable (rest points into it).
struct ContactBlock {
  explicit ContactBlock(int level = 3, int subdivisions = 8) : ContactBlock(level, subdivisions, spec_for(level, 40, 20, 10)) {}
  /// The same with the lattice keys of `lattice` (its level and radius are the block's; its floor is held).
  ContactBlock(int level, int subdivisions, LatticeSpec lattice)
      : box(make_box_model(kContactBlockSide_m, std::max(level, 4), subdivisions)),
        spec([level, &lattice] {
          LatticeSpec s = lattice;
          s.level = level;
          s.radius_cells = 64;
          s.fix_floor = true;  // held at the bottom, so the stiffness is not singular
          return s;
        }()),
        lat(build_lattice(box.grid, spec, region_cells(box.grid, level, {1, 1, 1}, 1 << level)).value()),
        bindings(bind_vertices(box.grid, level, box.mesh.vertices_m)),
        rest{&box.mesh, &box.grid, &bindings} {}
  ContactBlock(const ContactBlock&) = delete;
  ContactBlock& operator=(const ContactBlock&) = delete;

  BoxModel box;
  LatticeSpec spec;
  Lattice lat;
  std::vector<VertexBinding> bindings;
  RestObject rest;

  // a triangle of the top face (z = +0.04) whose centroid is nearest (x, y)
  int32_t top_triangle(double x, double y) const {
    int32_t best = -1;
    double best_d = 1e9;
    for (std::size_t t = 0; t < box.mesh.triangles.size(); ++t) {
      const auto& tri = box.mesh.triangles[t];
      Vec3 c = Vec3::Zero();
      bool top = true;
      for (int k = 0; k < 3; ++k) {
        top = top && std::abs(box.mesh.vertices_m[tri[k]].z() - kContactBlockSide_m / 2) < 1e-12;
        c += box.mesh.vertices_m[tri[k]] / 3.0;
      }
      const double d = std::hypot(c.x() - x, c.y() - y);
      if (top && d < best_d) best = static_cast<int32_t>(t), best_d = d;
    }
    return best;
  }
};

}  // namespace palpate::test
