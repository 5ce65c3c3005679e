#pragma once
/// The god-object's constrained move (Zilles and Salisbury's god-object, with a sphere's clearance): the proxy — a
/// sphere's centre, radius r; a point is a sphere of vanishing radius — moves from where it was toward the device
/// as far as the surface lets it. It sweeps toward the goal, stops at the first triangle it would come nearer than
/// r to, slides on the plane tangent there, and holds at most three such planes; when the goal pulls it off one
/// (a negative multiplier), it leaves it. Each plane comes from the contact point where the sweep meets it, so a
/// proxy slides flat across coplanar neighbours, rolls round a convex edge and settles in a crease or a dent. A
/// still device leaves the proxy where it is: the previous answer starts the move, and moving into the planes
/// that hold it is no move. Thread: servo (noexcept, no allocation).

#include "core/types.h"
#include "haptics/servo/local_model.h"

namespace palpate {

/// Moves from `from` toward `goal`, keeping r from every triangle of m on the contact's side (faces turned more
/// than 120 degrees from `side` are the far side of a thin part and never stop it). *active receives how many
/// planes hold the answer (0: the goal was reached; a move that runs out of rounds, where the slide got to, is held
/// by at least 1). max_path_m > 0 bounds the way the centre goes along the surface this call (a proxy that would
/// snap over a convex ridge rolls over it a bounded step a tick); a move cut short ends on the surface, dropped
/// from where the bound stopped it to r from the nearest face point on the contact's side.
Vec3 god_object_move(const LocalModel& m, const Vec3& from, const Vec3& goal, double r, const Vec3& side,
                     int* active, double max_path_m = 0.0) noexcept;

/// Pushes c out of the triangles it comes nearer than r to (after the surface moved under a held proxy), the
/// deepest first, up to `rounds` times. Returns the largest overlap left (m).
double push_out(const LocalModel& m, double r, const Vec3& side, int rounds, Vec3* c) noexcept;

/// Whether the god-object at c touches the surface at one convex spot: a sphere touching one place (a face, a convex
/// edge or corner), or a point (a sphere of vanishing radius) whose faces within `reach` never turn toward each other
/// — not a crease, a concave corner or a dent the tool fills. Faces turned from `side` by more than 120 degrees are
/// never taken.
bool convex_contact(const LocalModel& m, const Vec3& c, double reach, const Vec3& side, bool point) noexcept;

}  // namespace palpate
