#pragma once
/// Contact load: where a tool's push goes on the lattice. A point tool loads the cell nodes of the contact point's
/// triangle corners (barycentric x trilinear weights); a sphere tool loads the nodes under its Hertz contact patch.
/// Plain functions of the lattice and the object at rest; no state. Thread: the sim thread.

#include <array>
#include <cstdint>
#include <vector>

#include "core/binding.h"
#include "core/grid_hierarchy.h"
#include "core/tri_mesh.h"
#include "core/types.h"
#include "sim/contact/contact_compliance.h"
#include "sim/lattice/lattice.h"

namespace palpate {

/// The object at rest as the contact load reads it; every pointer must outlive the calls.
struct RestObject {
  const TriMesh* mesh = nullptr;                      ///< the rest mesh (world)
  const GridHierarchy* grid = nullptr;                ///< the grid over it
  const std::vector<VertexBinding>* bindings = nullptr;  ///< each vertex's cell at the lattice level (n_v)
};

/// Where a tool meets the object: the rest triangle and barycentric point the servo reported, and the tool.
struct ToolContact {
  int32_t tri = -1;               ///< triangle (of the rest mesh) holding the contact point
  Vec3 bary = Vec3::Zero();       ///< the contact point in it
  Vec3 centre_m = Vec3::Zero();   ///< sphere tool: its centre (the servo's proxy), world
  bool sphere = false;            ///< a sphere tool (else a point)
  double radius_m = 0.0;          ///< sphere tool radius
};

/// The point (tri, bary) of the surface whose corners are `vertices_m` (rest or deformed positions).
Vec3 surface_point(const std::vector<Vec3>& vertices_m, const std::array<int32_t, 3>& tri, const Vec3& bary);

/// Lattice nodes and weights (summing to 1 inside the lattice) of the material point (tri, bary): each corner's
/// cell nodes by trilinear weights, times the corner's barycentric weight. Corners outside the lattice add none.
PointWeights point_weights(const Lattice& lat, const RestObject& rest, int32_t tri, const Vec3& bary);

/// Sphere tool: the nodes under its contact patch at rest, weights summing to 1. The patch is a disc of radius
/// a = sqrt(R delta) (delta: how deep the sphere's lowest point is below the rest plane of the contact face) around
/// the foot of the centre on that plane, loaded with Hertz's pressure sqrt(1 - rho^2 / a^2) (Johnson, Contact
/// Mechanics, eq. 4.22), sampled on rings and spread to the nodes of the cells holding the samples by trilinear
/// weights. No sample inside the lattice (or no depth): point_weights of the contact point.
PointWeights hertz_patch_weights(const Lattice& lat, const RestObject& rest, const ToolContact& c);

/// Sphere tool: the foot of its centre on the rest plane of the contact face, the middle of its contact patch (steady
/// where the servo's nearest surface point wanders over the dimple the sphere presses). A point tool, or a degenerate
/// face: the contact point at rest.
Vec3 contact_patch_centre(const RestObject& rest, const ToolContact& c);

/// Where a contact's force goes: hertz_patch_weights for a sphere tool, else point_weights.
PointWeights contact_load_weights(const Lattice& lat, const RestObject& rest, const ToolContact& c);

/// The force the object receives for the device's reaction reaction_N: all of it for a point tool; for a sphere
/// tool its component along the rest normal of the face under the sphere (frictionless contact; at rest, since the
/// tilt of deformed facets would swing a large sphere's push sideways and back every frame).
Vec3 object_force(const RestObject& rest, const ToolContact& c, const Vec3& reaction_N);

}  // namespace palpate
