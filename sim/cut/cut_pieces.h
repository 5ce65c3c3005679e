#pragma once
/// PieceLattice: the part of a cut lattice that moves, stepped on its own. In cut mode the body keeps its rest
/// shape (the model as given is taken to be resting already; the blade pushes no force into the lattice and a cut
/// spring at its rest length releases none), so only the pieces cut free of every fixed node move: they fall under
/// gravity onto the floor and the body (piece_contact.h). A frame's step costs what those pieces hold, not the
/// object.

#include <cstdint>
#include <vector>

#include "sim/lattice/lattice.h"

namespace palpate {

/// The nodes and springs of the pieces cut free, as a lattice of their own, and the copy of its state to and from
/// the whole lattice. Copyable. Thread: the sim thread.
class PieceLattice {
 public:
  /// Rebuilds the piece lattice when the free nodes (ascending, as PieceContact::free_nodes() gives them) differ
  /// from the last ones or the springs among them do (a piece cut again), its state taken from `whole`. Returns
  /// true when it was rebuilt (its solver's caches then start again: Lattice::touch()).
  bool update(const Lattice& whole, const std::vector<int32_t>& free_nodes);
  /// True when there are pieces to step.
  bool empty() const { return nodes_.empty(); }
  /// The pieces' lattice (no node fixed; the whole lattice's gravity, damping and cells the pieces hold whole).
  Lattice& lattice() { return part_; }
  const Lattice& lattice() const { return part_; }
  /// Node of the whole lattice of each piece node.
  const std::vector<int32_t>& whole_nodes() const { return nodes_; }
  /// Writes the pieces' positions and velocities into the whole lattice.
  void push(Lattice* whole) const;
  /// Reads the pieces' positions and velocities back from the whole lattice (after the floor and the body moved
  /// them).
  void pull(const Lattice& whole);

 private:
  std::vector<int32_t> nodes_;     // whole-lattice node of each piece node (n_p)
  Lattice part_;                   // the pieces' lattice
};

}  // namespace palpate
