#pragma once
/// The lattice's strain as a picture can show it: the equivalent (von Mises) Green-Lagrange strain of each cell's
/// trilinear deformation at its centre, averaged at the nodes and interpolated to the surface.

#include <vector>

#include "core/types.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// Equivalent strain sqrt(2/3 dev(E) : dev(E)) of E = (F^T F - I) / 2, F the deformation gradient of the trilinear
/// map from the 8 rest corners to the 8 current ones (corner = dx + 2dy + 4dz), at the cell's centre. 0 for a rigid
/// motion; a uniaxial stretch e (no lateral strain) gives 2/3 |e + e^2/2|. 0 for a cell whose rest corners are
/// degenerate.
double cell_equivalent_strain(const std::array<Vec3, 8>& rest_m, const std::array<Vec3, 8>& x_m);

/// Each node's equivalent strain: the mean over the region cells at it (0 where none). *out is resized to the
/// lattice's nodes; *count is scratch.
void node_equivalent_strain(const Lattice& lat, std::vector<double>* out, std::vector<int>* count);

}  // namespace palpate
