#pragma once
/// PieceContact: keeps the pieces a cut frees out of the body they came from. The body is the lattice cells whose
/// eight nodes all hang on to a fixed node through springs; a node of a free piece inside such a cell (its box as
/// deformed now, a twentieth of a cell of skin at its sides) is put back out: against gravity when it is falling
/// or less than half a cell in, else along the shallowest way out through the run of body cells; its speed into
/// the body is removed and its sliding speed halved (friction), as the floor holds nodes (cut.h apply_floor()).
///
/// What it guarantees: a free node never stays inside a body cell after apply(), so a piece rests on the body's
/// cells; a piece's surface is bound within its own cells, so it may overlap the body's surface by at most a cell
/// where the two meet (the cells the cut passed through belong to neither).

#include <cstdint>
#include <vector>

#include "core/grid_hierarchy.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// Body cells and free nodes of a cut lattice. Copyable. Thread: the sim thread.
class PieceContact {
 public:
  /// Finds the body cells and the free nodes (call after springs were cut). grid must be the lattice's.
  void update(const Lattice& lat, const GridHierarchy& grid);
  /// Pushes free nodes out of body cells. Returns the number of nodes pushed.
  int apply(Lattice* lat, const GridHierarchy& grid) const;
  /// Nodes in pieces cut free (no fixed node reachable through springs).
  const std::vector<int32_t>& free_nodes() const { return free_; }
  /// True when region slot s is a body cell.
  bool body_cell(int32_t slot) const { return slot >= 0 && body_[static_cast<std::size_t>(slot)] != 0; }

 private:
  std::vector<uint8_t> body_;   // per region slot: all eight nodes anchored
  std::vector<int32_t> free_;   // free nodes, ascending
};

}  // namespace palpate
