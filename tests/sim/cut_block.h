#pragma once
// The block the cut tests slice: an 8 cm cube, its level-3 lattice (2 cm cells) over all of it, 1 cm mesh quads,
// and its cut model.

#include <vector>

#include "core/binding.h"
#include "sim/cut/cut_model.h"
#include "sim/lattice/lattice.h"
#include "sim_test_util.h"

namespace palpate::test {

inline constexpr double kCutBlockSide_m = 0.08;  // from -0.04 to 0.04
inline constexpr int kCutBlockLevel = 3;

/// The block, its lattice, its cut model and the mesh's vertices as the cut sees them.
struct CutBlock {
  BoxModel box = make_box_model(kCutBlockSide_m, 4, 8);
  LatticeSpec spec = spec_for(kCutBlockLevel, 40, 20, 10);
  Lattice lat = build_lattice(box.grid, spec, region_cells(box.grid, kCutBlockLevel, {1, 1, 1}, 8)).value();
  CutModel cut{box.mesh, bind_vertices(box.grid, kCutBlockLevel, box.mesh.vertices_m), &box.grid, kCutBlockLevel, 0.2};
  std::vector<Vec3> vertices = box.mesh.vertices_m;
};

}  // namespace palpate::test
