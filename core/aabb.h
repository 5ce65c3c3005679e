#pragma once
/// Axis-aligned bounding boxes and the normalisation of a mesh into a cube (paper step 1).

#include <string>
#include <vector>

#include "core/result.h"
#include "core/tri_mesh.h"
#include "core/types.h"

namespace palpate {

/// Closed axis-aligned box [min_m, max_m]; plain data, copyable.
struct Aabb {
  Vec3 min_m = Vec3::Zero();  ///< minimum corner, metres
  Vec3 max_m = Vec3::Zero();  ///< maximum corner, metres

  /// Side lengths max_m - min_m, metres.
  Vec3 extent() const;
  /// Centre (min_m + max_m) / 2, metres.
  Vec3 center() const;
  /// True when p lies in the closed box (faces included).
  bool contains(const Vec3& p) const;
  /// The smallest box holding all points; for no points min_m = +inf and max_m = -inf (an empty box).
  static Aabb of(const std::vector<Vec3>& points);
};

/// How raw model coordinates were mapped: world = scale * raw + offset_m (to rounding); plain data.
struct Normalization {
  double scale = 1;              ///< uniform scale factor (world metres per raw unit)
  Vec3 offset_m = Vec3::Zero();  ///< translation applied after scaling, metres
  Aabb cube;                     ///< cube of side size_m centred at the origin that holds the mesh
};

/// Paper step 1: scales the mesh uniformly so its largest AABB side equals size_m exactly and centres its AABB
/// at the origin; every vertex ends inside `cube`. Errors start with "mesh '<name>': " and end with
/// "size <s> is not a positive finite number", "no vertices", "no triangles",
/// "triangle 5 vertex index 40 is beyond the vertex list (size 32)", "vertex 12 is not finite",
/// "all vertices at one point" or "flat on axis z (extent 0 of 1.23)" (an extent below 1e-6 of the largest).
/// On error the mesh is left unchanged.
Result<Normalization> normalize_mesh(TriMesh* mesh, double size_m, const std::string& name);

}  // namespace palpate
