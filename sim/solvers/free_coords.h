#pragma once
/// The free coordinates q of a lattice's static problem (sim/solvers/static_solve.h, sim/contact/sphere_contact.h): the DOFs that are
/// neither held nor hanging. A hanging node (sim/lattice/hanging.h) moves with its coarse face, so the DOFs are x = P q (held
/// DOFs kept where they are): the tangent is assembled over every DOF not held, hanging ones included, and reduced to
/// P^T K P; the forces are folded to P^T f; a step in q moves the hanging nodes with their masters. Without hanging
/// nodes P is the identity and nothing is formed. A hanging node's own held flags are ignored: it follows its masters.
/// Thread: any; allocates.

#include <cstdint>
#include <vector>

#include <Eigen/SparseCore>

#include "sim/lattice/lattice.h"

namespace palpate {

/// The numbering of a lattice's DOFs in the assembled and in the reduced system. Plain data; copyable.
struct FreeCoords {
  std::vector<int> col;           ///< assembled row of each DOF (3n, dof 3i + axis), -1 where held
  std::vector<int> q_of;          ///< reduced index of each assembled lattice row, -1 for a hanging DOF (lattice_rows)
  int lattice_rows = 0;           ///< assembled rows of the lattice's DOFs; `extra` rows (e.g. a free sphere) follow
  int extra = 0;                  ///< unknowns beyond the lattice's, the last ones of both systems, carried as they are
  int free = 0;                   ///< reduced unknowns q, extra included
  Eigen::SparseMatrix<double> p;  ///< (lattice_rows + extra) x free, empty when the lattice has no hanging nodes
  int assembled() const { return lattice_rows + extra; }
};

/// Numbers lat's DOFs: held where held_dof (3n; empty: every DOF of lat.fixed nodes) says so, unless the node hangs;
/// `extra` unknowns appended. A hanging node's row of P is its masters' (theirs when they hang too) by the weights.
FreeCoords free_coords(const Lattice& lat, const std::vector<uint8_t>& held_dof, int extra = 0);

/// P^T K P of the assembled tangent k (assembled() square); k itself without hanging nodes.
Eigen::SparseMatrix<double> reduce_stiffness(const FreeCoords& fc, Eigen::SparseMatrix<double> k);

/// P^T f on the lattice's unknowns: f (n, modified) folded onto the hanging nodes' masters, its free entries written
/// to r->head(free - extra); r (free) must be sized.
void reduce_forces(const Lattice& lat, const FreeCoords& fc, std::vector<Vec3>* f, Eigen::VectorXd* r);

/// Sets lat->x_m to from_m (n, consistent with its hanging nodes) plus step * P dq on the lattice's unknowns: the free
/// DOFs moved, the hanging nodes following their masters.
void move_free(const FreeCoords& fc, const std::vector<Vec3>& from_m, const Eigen::VectorXd& dq, double step, Lattice* lat);

}  // namespace palpate
