#pragma once
/// CutRedraw: which vertices of a cut mesh a frame may move, so the renderer draws the rest once into its cached
/// layer and each frame only what changed (render/renderer.h, FrameView::moving_vertices). A cut changes the
/// triangles only where the blade goes, and the lattice moves only near the cut and in pieces that fall; the
/// rest of a large model stays still and is not drawn again.
///
/// The moving part is a set of lattice cells: those with a node that moved more than kRedrawTolerance of the
/// model's size since the layer was drawn, and those the blade's edge reaches while it cuts, each grown by a cell.
/// Its vertices are those bound to the cells and those of every triangle whose box overlaps one, so a triangle the
/// blade splits has all its corners moving before it is split. Within a layer the set only grows; when it must
/// grow, the layer epoch changes and the renderer redraws the layer. Between, the triangles change only where a
/// vertex moves (FrameView::static_part_kept): the layer is kept.
///
/// A redraw costs a whole mesh's draw (50-300 ms on a 50k-200k-triangle scan here), so the set it starts is made to
/// last: it takes the cells the edge sweeps over the next kBladeLeadFrames frames at its recent speed (and
/// kBladeReachCells cells around it in every direction), and it drops the cells nothing moved in since the last
/// redraw and the blade no longer reaches, so the part drawn every frame follows the blade instead of growing with
/// every cell it ever crossed. A new set with the same vertices as the old (the blade's reach still in the air)
/// keeps the layer.

#include <cstdint>
#include <vector>

#include "core/types.h"
#include "sim/cut/cut_model.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// A node closer than this fraction of the model's size to where it was when the layer was drawn counts as
/// still (a 10 cm model: 0.1 mm, under half a pixel at 640 x 480 in the generated scenes' view).
inline constexpr double kRedrawTolerance = 1e-3;
/// Cells around the blade's edge made moving in every direction when the part is redrawn (its motion has the lead
/// below): one; with two, a 50k-triangle scan's frames took 2.4-3.2 ms of render CPU (p50) instead of 1.6.
inline constexpr int kBladeReachCells = 1;
/// Frames of the blade's recent motion (its mean over kBladeSpeedFrames frames) made moving ahead of it when the
/// part is redrawn: at a hand's 50 mm/s, 25 mm (four 6 mm cells of a level-5 grid over a 10 cm model).
inline constexpr int kBladeLeadFrames = 30;
/// Frames the blade's speed is averaged over.
inline constexpr int kBladeSpeedFrames = 6;

/// The moving cells and vertices of a cut mesh for the renderer's layer. Copyable. Thread: the sim thread.
class CutRedraw {
 public:
  /// Starts with nothing moving, the layer drawn at the lattice's current positions; tolerance_m as above.
  CutRedraw(const Lattice& lat, int64_t num_cells, double tolerance_m);
  /// After a frame: grows the moving part by the cells whose nodes moved and those the blade edge tip-end reaches
  /// (when cutting), checks that the quads the frame cut with lay in it, and adds the vertices the frame's split
  /// created (from first_new on). Changes layer_epoch() when the part grew, topology_epoch() when the triangles
  /// changed.
  void update(const Lattice& lat, const CutModel& cut, bool cutting, const Vec3& tip_m, const Vec3& end_m,
              bool topology_changed, std::size_t first_new);
  /// The vertices a frame may move, ascending.
  const std::vector<int32_t>& moving_vertices() const { return moving_; }
  /// Changes whenever the moving part grew (the renderer redraws its layer).
  uint64_t layer_epoch() const { return layer_epoch_; }
  /// Changes whenever the triangles changed.
  uint64_t topology_epoch() const { return topology_epoch_; }
  /// Times the layer epoch changed.
  int64_t layer_changes() const { return static_cast<int64_t>(layer_epoch_); }
  /// The moving cells (cells of the lattice's level, in the order they were made moving).
  const std::vector<int32_t>& moving_cells() const { return cells_; }

 private:
  // marks the cells and their neighbours (grown by grow cells) moving
  void mark(const Lattice& lat, const std::vector<int32_t>& cells, int grow);
  // appends the cells within a cell of the edge tip_m-end_m (points half a cell apart along it) to need_
  void edge_cells(const Lattice& lat, const CutModel& cut, const Vec3& tip_m, const Vec3& end_m);
  // a new part: what moved since the layer was drawn, the quads of this frame and the blade's reach ahead
  void restart(const Lattice& lat, const CutModel& cut, bool cutting, const Vec3& tip_m, const Vec3& end_m);
  // the vertices of the moving cells and of the triangles overlapping them, ascending
  void collect(const Lattice& lat, const CutModel& cut);

  double tolerance_m_;
  std::vector<uint8_t> moving_cell_;  // per grid cell at the lattice's level (n_cells)
  std::vector<int32_t> cells_;        // the moving cells
  std::vector<Vec3> x_layer_m_;       // node positions when the layer was drawn (n)
  std::vector<int32_t> moving_;       // moving vertices, ascending
  std::vector<int32_t> previous_;     // scratch: the moving vertices before the part was made anew
  std::vector<int32_t> need_;         // scratch: cells that must be moving
  Vec3 tips_m_[kBladeSpeedFrames + 1];  // the blade tip of the last frames, a ring (newest at tip_count_ - 1)
  int64_t tip_count_ = 0;             // frames whose tip the ring has seen
  uint64_t layer_epoch_ = 0;
  uint64_t topology_epoch_ = 0;
};

}  // namespace palpate
