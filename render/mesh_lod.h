#pragma once
/// Screen-size level of detail: the triangles a mesh finer than the image is drawn with. On a 940k-triangle bunny
/// at 640 x 480 the median edge is half a pixel, and a software rasteriser pays per triangle, not per pixel: the
/// frame costs what its 45 000 covering sub-pixel triangles cost, not what the image shows. Vertex clustering
/// (Rossignac and Borrel) on a world grid of about a pixel's size gives a mesh whose median edge is about a pixel
/// and that lies within a cell of the original everywhere. Each cluster keeps one of its own vertices, so the
/// result indexes the input's vertices: it deforms with their bindings and is shaded with their normals exactly
/// as they are, and only its triangles differ.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/types.h"

namespace palpate {

/// The triangles a mesh is drawn with, and what they change.
struct MeshLod {
  /// Triangles over the input's vertex indices (its clusters' representatives only), in the order of the input
  /// triangles they come from; each unordered vertex triple once, wound to face the side its first source
  /// triangle faces.
  std::vector<std::array<int32_t, 3>> triangles;
  std::size_t representatives = 0;  ///< vertices the triangles use
  double cell_m = 0.0;              ///< edge of the clustering grid's cubes
  double median_edge_px = std::numeric_limits<double>::quiet_NaN();      ///< the input's median on-screen edge
  double lod_median_edge_px = std::numeric_limits<double>::quiet_NaN();  ///< the result's
  /// Farthest any used input vertex lies from its representative, in metres and on screen (pixels, at rest): a
  /// bound of how far the drawn surface moves.
  double max_shift_m = 0.0;
  double max_shift_px = 0.0;
};

/// Pixel position of a world point (NaN when it cannot be placed), e.g. Renderer::project.
using ProjectFn = std::function<Eigen::Vector2d(const Vec3&)>;

/// Median on-screen length, in pixels, of the triangles' edges (each triangle's three; edges that cannot be
/// placed are left out). NaN when there is none.
double median_edge_px(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int32_t, 3>>& triangles,
                      const ProjectFn& project);

/// The mesh to draw instead of `triangles` (indices valid for vertices_m) when its median on-screen edge is
/// shorter than min_edge_px: clustered until the result's median edge is at least about min_edge_px. nullopt
/// when min_edge_px <= 0, when the mesh's median edge is not shorter, or when no edge can be placed.
std::optional<MeshLod> screen_lod(const std::vector<Vec3>& vertices_m,
                                  const std::vector<std::array<int32_t, 3>>& triangles, const ProjectFn& project,
                                  double min_edge_px);

}  // namespace palpate
