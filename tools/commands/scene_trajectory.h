#pragma once
/// The trajectory of a generated scene: how deep a touch or pull goes at its surface point (bounded by the body under
/// it), which way a cut draws its blade (where its path stays on the surface longest), and the keyframes.
/// Thread: any (off the real-time path).

#include <optional>

#include <nlohmann/json.hpp>

#include "core/aabb.h"
#include "core/scene.h"
#include "core/types.h"
#include "render/camera.h"
#include "runtime/session/model.h"

namespace palpate {

/// interaction.grab_radius_m of a generated scene (and the reach a surface point must be felt within), metres.
inline constexpr double kGrabRadius_m = 0.008;
/// A touch's press or a pull's lift: at most this fraction of the body's thickness under the point.
inline constexpr double kDepthOfThickness = 0.5;

/// The body under a surface point: from point_m along the unit approach d to the first surface beyond it (either
/// facing), metres; +inf when the ray leaves through nothing (an open sheet) within reach_m.
double thickness_under(const Model& model, const Vec3& point_m, const Vec3& d, double reach_m);

/// The blade's stroke of a generated cut: its unit direction (across the approach) and how far along it, from the
/// entry point, the blade keeps crossing the surface (the incision's length).
struct CutStroke {
  Vec3 across = Vec3::UnitX();  ///< unit direction the blade is drawn in, perpendicular to the approach
  double run_m = 0.0;           ///< from the entry point, the length over which the blade crosses the surface
};

/// How far from P along `across` a blade reaching depth_m under P's plane (along the unit approach d) and
/// clearance_m above it keeps crossing a surface that faces the approach (gaps up to 2 mm bridged), within limit_m.
double blade_run_m(const Model& model, const Vec3& P, const Vec3& d, const Vec3& across, double depth_m,
                   double clearance_m, double limit_m);

/// The stroke of a cut entering at P along d: of 16 directions across d, the one with the longest blade_run_m (so
/// a thin wall is cut along its length, not across its thickness); on a tie within a millimetre, the box's longest
/// side, toward its farther face (the stroke cuts scans as before).
CutStroke choose_cut_stroke(const Model& model, const Aabb& box, const Vec3& P, const Vec3& d, double depth_m,
                            double clearance_m);

/// The direction a generated cut is seen from (unit, from the model toward the camera): the side the blade comes in
/// (-d) turned toward the default front-right-above view, so the groove has depth and a flat part's top is not seen
/// edge-on; when that view would meet the face at the entry point (unit normal) at more than 60 degrees (a sheet
/// whose back the default view faces was seen edge-on), straight at the face instead.
Vec3 cut_view_from(const Vec3& d, const Vec3& normal);

/// What a generated cut's camera frames: a sphere around the incision (render.look_at_m, render.frame_radius_m).
struct CutFrame {
  Vec3 look_at_m = Vec3::Zero();  ///< the sphere's centre (world), metres
  double radius_m = 0.0;          ///< its radius, metres
};

/// The sphere around the incision of a cut entering at P along the unit d by depth_m: the stroke's run on the surface
/// and the blade's depth, with as much again of the model around; nullopt when it is not under half the model's
/// bounding sphere (the whole model is framed, the incision already large in it).
std::optional<CutFrame> cut_frame(const Vec3& P, const Vec3& d, const CutStroke& stroke, double depth_m, const Aabb& box);

/// The incision of a blade drawn from `in` to `out` (tip positions, the blade along -d up to blade_length_m) as a
/// camera sees it at width x height pixels: probed every 0.5 mm, where the blade crosses a surface facing it; the
/// projected length of those parts, pixels.
double incision_px(const Model& model, const Camera& cam, int width, int height, const Vec3& in, const Vec3& out,
                   const Vec3& d, double blade_length_m);

/// Writes the interaction section and the keyframes: from clearance_m out along the approach d to the surface point
/// P, then a press of depth_m (touch), a grab pulled out by depth_m (pull), or a blade in by depth_m drawn along
/// stroke.across to the box's far side (cut), and away again. Returns the scene's duration, seconds.
double add_trajectory(InteractionMode mode, const Vec3& P, const Vec3& d, double clearance_m, double depth_m,
                      const CutStroke& stroke, const Aabb& box, nlohmann::ordered_json* j);

}  // namespace palpate
