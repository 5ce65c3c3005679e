#pragma once
/// `palpate scene`: writes a touch, pull or cut scene that works on any mesh — up axis, levels and a trajectory
/// toward a surface point found on the model as loaded.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/result.h"
#include "core/scene.h"
#include "core/types.h"

namespace palpate {

/// What a scene is asked for (checked by generate_scene).
struct SceneRequest {
  std::string mesh_path;                     ///< the model (anything `palpate info` reads)
  InteractionMode mode = InteractionMode::kTouch;
  std::optional<Vec3> at_raw;                ///< --at: approach the surface point nearest this (mesh file's units)
  std::optional<Vec3> from;                  ///< --from: unit direction (world, after the up rotation) the tool comes from
  double depth_mm = 0.0;                     ///< press / pull / cut depth; 0 = the mode's default
  int level = 0;                             ///< lattice level; 0 = sized to the model
  char up_axis = 0;                          ///< the file's up axis x|y|z; 0 = guessed from its extent
  std::string scene_dir = ".";               ///< folder the scene will be written to (the mesh path is made relative to it)
  double young_modulus_Pa = 0.0;             ///< --young-modulus: a material in physical units (0: the raw springs)
  double poisson_ratio = 0.45;               ///< --poisson, with a material
  double density_kg_per_m3 = 1050.0;         ///< --density, with a material
  bool sphere_tool = false;                  ///< --tool sphere (else a point)
  double tool_radius_mm = 2.0;               ///< --tool-radius-mm
  bool solved_contact = false;               ///< --contact solved (touch only)
};

/// A scene as generated, and what was decided on the way.
struct GeneratedScene {
  nlohmann::ordered_json json;               ///< the scene file's content
  std::vector<std::string> notes;            ///< one line each: up axis, levels, the point chosen
  Vec3 surface_point_m = Vec3::Zero();       ///< the surface point the trajectory works at (world)
  Vec3 approach = -Vec3::UnitZ();            ///< unit direction of the approach (into the surface)
  Vec3 surface_normal = Vec3::UnitZ();       ///< unit normal of the face at surface_point_m (its front side)
};

/// Builds the scene. Errors name the mesh or the option ("--from +z: no surface of 'a.obj' faces +z").
Result<GeneratedScene> generate_scene(const SceneRequest& request);

/// "X,Y,Z" as three finite numbers; errors name the option and the text.
Result<Vec3> parse_point(const std::string& option, const std::string& text);
/// "+z", "-x", "y" (= +y) as a unit world direction; errors name the option and the text.
Result<Vec3> parse_direction(const std::string& option, const std::string& text);

/// Writes text to path through a temporary file renamed over it; an existing path is replaced only when it is a
/// regular file. Errors name the path.
Status write_text_replacing(const std::string& path, const std::string& text);

/// The command: generates, writes out_path (empty: <mesh stem>_<mode>.json here), says its decisions on stderr.
/// Returns the process exit code (0, or 1 with a one-line error on stderr).
int run_scene(SceneRequest request, const std::string& out_path);

}  // namespace palpate
