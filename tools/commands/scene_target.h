#pragma once
/// Where a generated scene works: the file's up axis guessed from its extent, and the surface point a tool coming
/// from one side meets and can feel. Thread: any (off the real-time path).

#include <optional>
#include <string>
#include <vector>

#include "core/aabb.h"
#include "core/types.h"
#include "runtime/session/model.h"
#include "runtime/session/surface_queries.h"

namespace palpate {

/// The up axis ('x', 'y' or 'z') of a mesh file from its raw box: a flat model lies on its thin axis; a model
/// standing on the plane through 0 of one axis (the others straddling 0) stands on that axis; otherwise the custom
/// of the format named by path's extension (z for CAD and print formats, y for the others). *why says which.
char guess_up_axis(const Aabb& raw_box, const std::string& path, std::string* why);

/// Whether the servo can feel a touch at hit: its surface patch holds at most LocalModel::kMaxTriangles of the
/// triangles near the tool (those within grab_radius_m or two leaf cells), the nearest by centroid, so a large face
/// among many small ones (a floor under lettering, a building's wall) can be left out and the tool pass through.
bool feelable(const Model& model, const SurfaceHit& hit, double grab_radius_m);

/// The first front-facing surface a tool coming from `from` (unit, world) meets and can feel, inside its triangle
/// (at least min(0.5 mm, a quarter of its inradius) from every edge, so never on an edge two triangles share): on the ray through
/// the box centre, then on rings of parallel rays around it, then through the centroids of the faces turned to
/// `from`, nearest the centre line first. *offset tells whether the ray missed the centre. Empty when none is found.
/// With `more`, the rings are searched on after the first hit and up to kMoreSurfacePoints further hits appended.
std::optional<SurfaceHit> surface_from(const Model& model, const Aabb& box, const Vec3& from, double grab_radius_m,
                                       bool* offset, std::vector<SurfaceHit>* more = nullptr);

/// How many further surface points surface_from gathers when asked.
inline constexpr std::size_t kMoreSurfacePoints = 24;

}  // namespace palpate
