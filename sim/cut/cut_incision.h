#pragma once
/// The incision: how a cut shows where the surface does not open. The two copies a split makes of a crossed
/// mesh edge's point (mesh_split.h) are placed below the crossing, sunk along the blade's swept surface into the
/// material (never past the blade's tip). The split triangles beside the cut then slope down into a V-groove along
/// the blade's path, whose two flanks meet on the swept surface: the cut walls, drawn by the triangles the split
/// makes anyway (no triangle is added for them). The copies stay on the swept surface, so a later sweep along the
/// same cut splits nothing again.

#include <functional>

#include "core/types.h"
#include "sim/cut/cut.h"

namespace palpate {

/// Depth of the groove in lattice cells (at most; less where the blade's tip did not reach as deep).
inline constexpr double kIncisionDepthCells = 0.25;

/// The groove's depth and where its copies may go. Copyable; a zero depth draws no groove (the copies stay at the
/// crossing).
struct IncisionShape {
  double depth_m = 0.0;  ///< how far the copies sink along the swept surface at most, metres
  double gap_m = 0.0;    ///< the blade's width: the two copies are set this far apart across the swept surface, metres
  /// Where a copy may go (empty: anywhere): a point it refuses is taken back halfway to the crossing, three times
  /// at most, then to the crossing (cut_model.h: inside a cell of the lattice, so the copy moves with it).
  std::function<bool(const Vec3&)> keep;
};

/// Rest position of the copies of the crossing crossing_m of `quad` on a triangle of outward unit normal
/// surface_normal: sunk by up to shape.depth_m into the material along the quad, across its motion (at most the
/// crossed edge's length edge_m, less where the blade meets the surface at a grazing angle or runs into it head on,
/// or where its tip is shallower), then taken back toward the crossing while shape.keep refuses it. The crossing
/// itself for a degenerate quad or a zero depth. The point moves at most depth_m from the crossing.
Vec3 incision_point(const BladeQuad& quad, const Vec3& crossing_m, const Vec3& surface_normal, double edge_m,
                    const IncisionShape& shape);

/// Where the copy of a crossing on one side goes from `at` (incision_point's): half shape.gap_m across the swept
/// surface toward that side (toward_m, a vector from the crossing to the side's end of the crossed edge), so the two
/// sides of a cut stand apart by the blade's width (a sheet with no thickness, which no groove shows, opens a slit);
/// taken back toward `at` while shape.keep refuses it. `at` itself for a zero gap or a degenerate quad.
Vec3 incision_side_point(const BladeQuad& quad, const Vec3& at, const Vec3& toward_m, const IncisionShape& shape);

}  // namespace palpate
