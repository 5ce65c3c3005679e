#pragma once
/// Surface queries on a loaded model at rest (world frame): the first hit of a ray and the nearest surface point.
/// Used off the real-time path (scene generation, model-relative keyframes, the no-contact report; the sim thread's
/// check for a tool inside the object, once a frame). Thread: any.

#include <cstdint>
#include <optional>
#include <vector>

#include "core/types.h"
#include "runtime/session/model.h"

namespace palpate {

/// A point on the model's rest surface.
struct SurfaceHit {
  Vec3 point_m = Vec3::Zero();   ///< the point, world metres
  Vec3 normal = Vec3::UnitZ();   ///< unit face normal of its triangle (counter-clockwise side out)
  int32_t triangle = -1;         ///< triangle id in model.rest
  double distance_m = 0.0;       ///< from the query's origin (ray) or query point (nearest)
};

/// First triangle crossed by the segment origin_m -> origin_m + length_m * dir (dir need not be unit); with
/// front_only, only triangles entered from their front side count (as the servo's touch test does).
/// Empty when nothing is crossed or dir is zero.
std::optional<SurfaceHit> first_ray_hit(const Model& model, const Vec3& origin_m, const Vec3& dir, double length_m,
                                        bool front_only);

/// The closest point of the rest surface to p_m (exact, found through the grid's leaf lists);
/// empty only for a model without triangles.
std::optional<SurfaceHit> nearest_surface_point(const Model& model, const Vec3& p_m);

/// A depth p_m provably lies under the rest surface, inside a closed model: layers x the leaf cell's edge when every
/// leaf cell within `layers` = ceil(reach_m / leaf) + 1 of p's own is solid and not crossed by the surface (so p is
/// farther than reach_m from the surface); 0 when one is not, p is outside the grid, or layers would pass 24 (49^3
/// cells). Nothing allocated.
double proven_depth_inside(const Model& model, const Vec3& p_m, double reach_m);

/// How many times the segment p0_m -> p1_m crosses the rest surface, from either side: crossings at the same place of
/// the segment (through an edge or corner shared by faces) count once. Candidates from the grid's leaves the segment's
/// box touches; ids is their scratch list (nothing else allocated once it has grown).
int path_crossings(const Model& model, const Vec3& p0_m, const Vec3& p1_m, std::vector<int32_t>* ids);

/// How deep p_m lies inside the object at rest, when deeper than reach_m: its distance to the rest surface, where the
/// grid says p is inside (a cell enclosed by the surface), or, in a cell the surface crosses, where the face nearest p
/// turns its back to p and rays along three axes cross the surface an odd number of times in at least two of them.
/// 0 otherwise: outside, within reach_m of the surface, outside the grid's cube, or on a surface that is not closed
/// (Model::closed: an open sheet has no inside).
/// Cheap for a point outside the object or near its surface (a cell and a nearest-point search); allocates.
/// still_m (when given) receives how far p may move with the answer still 0 (0 when inside, or when not known).
double depth_inside(const Model& model, const Vec3& p_m, double reach_m, double* still_m = nullptr);

}  // namespace palpate
