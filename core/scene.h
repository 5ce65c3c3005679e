#pragma once
/// Scene: everything a recording needs, parsed strictly from JSON (unknown keys and out-of-range values are errors).

#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "core/rates.h"
#include "core/result.h"
#include "core/scene_enums.h"
#include "core/types.h"

namespace palpate {


/// mesh.subdivisions "auto" (the default): see MeshSpec::subdivisions.
inline constexpr int kAutoSubdivisions = -1;

/// Where the model comes from and how it is normalised.
struct MeshSpec {
  std::string file;                   ///< mesh path (resolved against the scene's folder); empty for a box
  Vec3 box_size_m = Vec3::Zero();     ///< generated box sides when file is empty
  int box_subdivisions = 8;           ///< quads per box face edge
  double size_m = 0.1;                ///< largest side after normalisation
  char up_axis = 'z';                 ///< the file's up axis (x, y or z); rotated to world z on load
  int subdivisions = kAutoSubdivisions;  ///< midpoint subdivisions applied on load (each: 4x the triangles, same
                                         ///< shape); kAutoSubdivisions: a mesh file in touch or pull whose triangles
                                         ///< are coarser than the lattice's finest cells is subdivided until they are
                                         ///< not (runtime/session/model.h), else none
};

/// The object in physical units (scene key "material"); when set, build_lattice() derives spring constants,
/// node masses and damping from it (sim/material/material.h) instead of the raw lattice keys, which it excludes.
struct MaterialSpec {
  bool enabled = false;                 ///< true when the scene has a "material" object
  double young_modulus_Pa = 1e5;        ///< E
  double poisson_ratio = 0.25;          ///< nu asked for; represented by kVolumetric, springs alone give 0.25
  MaterialModel model = MaterialModel::kSprings;  ///< central springs only, or springs plus a per-cell volume term
  double density_kg_per_m3 = 1000.0;    ///< rho
  double stiffness_damping_s = 0.0;     ///< Rayleigh beta: a mode of angular frequency w gets damping ratio beta w / 2
};

/// The local mass-spring lattice (paper section 4.2) and its dynamics.
/// Refinement where the tool is (sim/lattice/refined_lattice.h, sim/lattice/graded_zone.h): the region's cells near the contact are
/// split a level at a time down to `level`, the rest stay at the lattice level. Plain data; level 0 = off.
struct RefineSpec {
  int level = 0;          ///< fine grid level (> lattice.level); 0 = a uniform lattice
  double radius_m = 0.0;  ///< cells closer than this to the contact (twice this into the body) are split to `level`,
                          ///< each coarser ring within twice the next one's reach; the zone moves when the contact
                          ///< goes more than half of it from where the zone was built
};

struct LatticeSpec {
  int level = 4;                        ///< grid level the lattice is built at
  int radius_cells = 2;                 ///< region: solid cells within this Chebyshev distance of the contact cell
  double node_mass_kg = 0.002;          ///< M, per node
  double structural_N_per_m = 40.0;     ///< K of axis springs; 0 switches the family off
  double shear_N_per_m = 20.0;          ///< K of face/body diagonal springs; 0 = off
  double bend_N_per_m = 10.0;           ///< K of skip-one springs; 0 = off
  double damping_Ns_per_m = 0.05;       ///< C_d, relative-velocity damping per spring (eq. 4)
  Vec3 gravity_m_per_s2 = Vec3::Zero(); ///< g (eq. 6)
  bool fix_floor = false;               ///< also fix nodes on the lowest z plane of the model
  IntegratorKind integrator = IntegratorKind::kSymplecticEuler;
  int max_substeps = 256;               ///< cap on automatic substeps per frame
  int substeps = 0;                     ///< fixed substeps per frame; 0 = automatic (explicit/symplectic/rk4: bound, others: 1)
  int iterations = 0;                   ///< Newton (implicit_euler) or local/global iterations; 0 = the integrator's default
  double strain_limit = 0.0;            ///< > 0: springs are kept within rest * (1 +- strain_limit); 0 = off
  double rest_kinetic_J = 1e-12;        ///< the lattice rests (is not stepped) below this kinetic energy ...
  double rest_force_N = 1e-6;           ///< ... and with every node's net force below this
  bool follow_contact = true;           ///< move/grow the region when the contact leaves it
  double budget_ms = 0.0;               ///< > 0: realtime frames step at the most accurate setting holding this sim budget
  bool allow_divergence = false;        ///< a recording whose lattice diverged (and was reset) still exits 0, with a warning
  RefineSpec refine;                    ///< "refine": fine cells around the contact (off by default)
  MaterialSpec material;                ///< the scene's top-level "material" object (exclusive with the raw k, M, C_d)
};

/// The scene's device block: the driver and its link, the limits asked and the proxy coupling (what the device
/// itself can do is haptics' DeviceSpecs).
struct DeviceSetup {
  DeviceDriver driver = DeviceDriver::kScripted;  ///< where the poses come from (names: core/scene_enums.h)
  std::string link;                         ///< shm: link name; plugin: .so path; replay: haptic.csv or recording folder
  double watchdog_ms = 5.0;                 ///< shm: peer silent this long -> force zero, "disconnected"
  double browser_stall_ms = 250.0;          ///< browser: the steering page silent this long -> its force fades out
                                            ///< (a busy browser's main thread pauses for 100 ms and more)
  double browser_send_ms = 15.0;            ///< browser: the page sends its pointer this often while its user steers
  double max_speed_m_per_s = 10.0;          ///< shm: poses implying a faster handle are rejected
  double max_force_N = 3.3;                 ///< force clamp
  double coupling_N_per_m = 300.0;          ///< k_c of the proxy spring
  double coupling_damping_Ns_per_m = 0.5;   ///< b_c on the tool velocity while in contact
  double tool_radius_m = 0.003;             ///< tool sphere radius: drawn, and the contact radius of a sphere tool
  bool sphere_tool = false;                 ///< touch with a sphere of tool_radius_m (key tool_shape "sphere"); else a point
  bool solved_contact = false;              ///< key contact "solved": the push goes where the surface, deformed by it,
                                            ///< meets the tool's tip (a sphere of tool_radius_m; sim/contact/solved_contact.h);
                                            ///< "prescribed" (default): a point load, or a sphere's Hertz pressure
  double workspace_half_m = 0.5;            ///< poses outside this cube around the origin are rejected
  double max_stiffness_N_per_m = 700.0;     ///< highest stable rendered stiffness; caps coupling_N_per_m
  double damping_Ns_per_m = 2.0;            ///< the device's own viscous damping at the handle (shm, plugin, replay;
                                            ///< the scripted device's is the hand's): b of the passivity bound 2b/T
  bool passivity = true;                    ///< energy-based passivity observer/controller on the coupling
  double ramp_s = 0.2;                      ///< force ramp-in at start and after a reset
  double jump_limit_N_per_tick = 0.02;      ///< a force step at a contact's entry or release, a grab, a region change
                                            ///< or a cut reaches the hand at most this much a servo tick (0: unlimited)
  double force_shading_deg = 0.0;           ///< touch: > 0 shades the force: faces meeting at less than this turn
                                            ///< are felt as one smooth surface (the force follows the normals
                                            ///< interpolated across a face), sharper edges stay edges (60 is a
                                            ///< renderer's usual crease); 0: felt as flat facets  /// browser: the page's stiffness control scales the material's stiffness (E, or a raw lattice's springs) within
  /// [lo, hi] (key browser_stiffness_range; the stiffest is checked stable when the run opens)
  double browser_stiffness_lo = 0.25;
  double browser_stiffness_hi = 4.0;
  /// browser: the page's tool radius within [lo, hi] m (key browser_tool_radius_range_m; 0, 0: half to twice
  /// tool_radius_m)
  double browser_radius_lo_m = 0.0;
  double browser_radius_hi_m = 0.0;
};

/// The scripted hand: a mass pulled toward keyframe targets by a spring-damper.
struct HandSpec {
  double mass_kg = 0.12;
  double stiffness_N_per_m = 150.0;
  double damping_Ns_per_m = 6.0;
};

/// One trajectory keyframe; positions are linearly interpolated, the button holds until the next key.
struct Keyframe {
  double t_s = 0.0;
  Vec3 pos_m = Vec3::Zero();
  bool button = false;
  Quat orientation = Quat::Identity();  ///< tool orientation (key "orientation_wxyz", normalised), slerped between keys
  std::optional<Vec3> pos_rel = std::nullopt;  ///< instead of pos_m: a point of the model's box (0..1 per axis, world axes)
  bool surface = false;                        ///< snap to the first surface the approach from the previous key crosses
  double depth_m = 0.0;                        ///< with surface: this far past the surface along the approach (< 0: short of it)
};

/// True when a keyframe's position is only known once the model is loaded (pos_rel or surface).
inline bool needs_model(const Keyframe& k) { return k.pos_rel.has_value() || k.surface; }

/// RenderSpec::antialias: edges smoothed in the image read back (render/edge_smooth.h), not multisampled.
inline constexpr int kAntialiasEdges = -1;

/// Off-screen rendering.
struct RenderSpec {
  int width = 640;
  int height = 480;
  RenderStyle style = RenderStyle::kSolid;
  RenderBackend backend = RenderBackend::kAuto;
  double wire_min_edge_px = kWireMinEdgePxDefault;  ///< `both`: no wireframe when the median edge is shorter (0: always)
  double lod_min_edge_px = kLodMinEdgePxDefault;    ///< drawn clustered when the median edge is shorter (0: never)
  Vec3 view_from = Vec3::Zero();                    ///< direction from the model toward the camera (zero: front-right-above)
  Vec3 look_at_m = Vec3::Zero();                    ///< with frame_radius_m: the point the camera frames (world, metres)
  double frame_radius_m = 0.0;                      ///< the camera frames a sphere this large around look_at_m (0: the whole model)
  RenderColor color = RenderColor::kAuto;           ///< the surface coloured by displacement from rest, or one colour
  double color_range_m = 0.0;                       ///< displacement at the colour map's top (0: planned from the trajectory)
  double strain_range = 0.0;                        ///< `strain`: equivalent strain at the map's top (0: planned, as above)
  bool force_arrow = true;                          ///< the force sent to the device as an arrow at the proxy, its value beside it
  bool legend = true;                               ///< the colour map's and the arrow's scales in the top-right corner
  bool floor = true;                                ///< a floor under the model with its and the tool's shadows
  bool force_trace = true;                          ///< an inset of the force's magnitude over the last two seconds
  int antialias = kAntialiasEdges;                  ///< anti-aliased edges: kAntialiasEdges (smoothed in the image),
                                                    ///< 0 (none), or 2, 4 or 8 samples a pixel (multisampled)
};

/// A whole scene.
struct Scene {
  std::string path;                 ///< the file it came from
  std::string name;
  MeshSpec mesh;
  int grid_levels = 5;
  LatticeSpec lattice;
  DeviceSetup device;
  HandSpec hand;
  InteractionMode mode = InteractionMode::kTouch;
  double grab_radius_m = 0.01;      ///< pull: grab when the surface is this close on button press
  double blade_length_m = 0.03;     ///< cut: blade edge from the tool tip along the tool's local +z axis
  double blade_width_m = 0.0;       ///< cut: the cut's two sides are set this far apart (0: they meet in the groove)
  double cut_resistance_Ns_per_m = 4.0;  ///< cut: material's viscous resistance to the blade moving through it
  double static_friction = 0.0;     ///< material.static_friction (touch): mu_s, the proxy sticks until the pull
                                    ///< across exceeds mu_s F_n
  double dynamic_friction = 0.0;    ///< material.dynamic_friction (touch): mu_d <= mu_s, the force against sliding
                                    ///< is mu_d F_n
  std::vector<Keyframe> trajectory;
  RenderSpec render;
  RunMode run_mode = RunMode::kLockstep;
  double duration_s = 1.0;
  std::vector<std::string> warnings;  ///< keys read from an old place, said once by the command that loads it
  Rates rates;                      ///< servo ticks (key servo.rate_hz) and frames per (scene-)second; the one copy
                                    ///< a run reads (--servo-rate is applied to it once, by the record plan)
};

/// A scene with every key at its default: the one owner of the defaults that other parameter blocks repeat
/// (haptics' ServoParams starts from these). Built once.
inline const Scene& scene_defaults() {
  static const Scene defaults{};
  return defaults;
}

/// Parses JSON text; `path` names the scene in errors ("scene 'x.json': lattice.level 9 out of range [1, 8]").
Result<Scene> parse_scene(const std::string& json_text, const std::string& path);
/// Reads and parses a scene file.
Result<Scene> load_scene(const std::string& path);
/// Why a scene's keys cannot go together ("device.tool_shape: 'sphere' is a touch tool; ..."), or "" when they can:
/// the checks parse_scene makes once every key is read (also asked of a scene a control changed, core/scene_controls.h).
std::string scene_conflict(const Scene& scene);

/// Name of an integrator as written in scenes.
const char* integrator_name(IntegratorKind kind);
/// The integrator called `name` in scenes; false (and *kind untouched) for an unknown name.
bool integrator_from_name(const std::string& name, IntegratorKind* kind);
/// Name of an interaction mode as written in scenes.
const char* mode_name(InteractionMode mode);
/// Writes the scene's warnings, one line each ("warning: scene 'x.json': ...").
void report_scene_warnings(const Scene& scene, std::FILE* to);

/// Whether the scene's frames colour the surface by displacement (render.color, auto: not in cut mode).
inline bool colors_by_displacement(const Scene& scene) {
  return scene.render.color == RenderColor::kDisplacement ||
         (scene.render.color == RenderColor::kAuto && scene.mode != InteractionMode::kCut);
}

/// Why render.color 'strain' is refused in cut mode.
inline constexpr const char* kStrainInCut =
    "render.color: 'strain' is not drawn in interaction.mode 'cut' (the cut lattice's cells come apart); use "
    "'displacement' or 'none'";
/// Whether the frames colour the surface by the lattice's equivalent strain (render.color 'strain').
inline bool colors_by_strain(const Scene& scene) { return scene.render.color == RenderColor::kStrain; }

}  // namespace palpate
