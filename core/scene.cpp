#include "core/scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/input_file.h"
#include "core/limits.h"
#include "core/scene_json.h"
#include "core/scene_reader.h"

namespace palpate {
namespace {

using namespace scene_reader;


void read_mesh(ObjectReader& top, Scene* s, std::string* err) {
  top.require("mesh");
  ObjectReader r(top.object("mesh"), "mesh.", err);
  r.string("file", &s->mesh.file);
  r.vec3("box_m", &s->mesh.box_size_m, 1e-4, 10.0);
  r.integer("box_subdivisions", &s->mesh.box_subdivisions, 1, 256);
  r.number("size_m", &s->mesh.size_m, 1e-3, 10.0);
  if (r.has_string("subdivisions")) {
    std::string how;
    r.string("subdivisions", &how);
    if (err->empty() && how != "auto") r.fail("mesh.subdivisions", "'" + printable_scene_text(how) + "' must be \"auto\" or 0..7");
  } else {
    r.integer("subdivisions", &s->mesh.subdivisions, 0, 7);
  }
  const int up = r.choice("up_axis", {"x", "y", "z"});
  if (up >= 0) s->mesh.up_axis = static_cast<char>('x' + up);
  if (err->empty() && s->mesh.file.empty() && s->mesh.box_size_m.isZero())
    r.fail("mesh", "needs either \"file\" or \"box_m\"");
  if (err->empty() && !s->mesh.file.empty() && !s->mesh.box_size_m.isZero())
    r.fail("mesh", "\"file\" and \"box_m\" are exclusive");
  r.finish();
}

void read_lattice(ObjectReader& top, Scene* s, std::string* err) {
  ObjectReader r(top.object("lattice"), "lattice.", err);
  LatticeSpec& l = s->lattice;
  r.integer("level", &l.level, 1, kMaxGridLevels);
  r.integer("radius_cells", &l.radius_cells, 1, 128);
  r.number("node_mass_kg", &l.node_mass_kg, 1e-7, 100.0);
  const Json& k = r.object("stiffness_N_per_m");
  if (!k.is_null()) {
    ObjectReader kr(k, "lattice.stiffness_N_per_m.", err);
    kr.number("structural", &l.structural_N_per_m, 0.0, 1e9);
    kr.number("shear", &l.shear_N_per_m, 0.0, 1e9);
    kr.number("bend", &l.bend_N_per_m, 0.0, 1e9);
    kr.finish();
  }
  r.number("damping_Ns_per_m", &l.damping_Ns_per_m, 0.0, 1e6);
  r.vec3("gravity_m_per_s2", &l.gravity_m_per_s2, -1e3, 1e3);
  r.boolean("fix_floor", &l.fix_floor);
  r.name("integrator", &l.integrator);
  r.integer("max_substeps", &l.max_substeps, 1, kMaxSubsteps);
  r.integer("substeps", &l.substeps, 0, kMaxSubsteps);
  r.integer("iterations", &l.iterations, 0, kMaxIterations);
  r.number("strain_limit", &l.strain_limit, 0.0, 10.0);
  r.number("rest_kinetic_J", &l.rest_kinetic_J, 0.0, 1.0);
  r.number("rest_force_N", &l.rest_force_N, 0.0, 1.0);
  r.boolean("follow_contact", &l.follow_contact);
  r.number("budget_ms", &l.budget_ms, 0.0, 1e4);
  if (err->empty() && l.budget_ms > 0.0 && l.integrator != IntegratorKind::kLocalGlobal)
    r.fail(r.path("budget_ms"), "needs \"integrator\": \"local_global\" (the budget trades its iterations for time)");
  r.boolean("allow_divergence", &l.allow_divergence);
  const Json& refine = r.object("refine");
  if (!refine.is_null()) {
    ObjectReader fr(refine, "lattice.refine.", err);
    fr.require("level");
    fr.require("radius_m");
    fr.integer("level", &l.refine.level, 2, kMaxGridLevels);
    fr.number("radius_m", &l.refine.radius_m, 1e-6, 10.0);
    fr.finish();
  }
  r.finish();
}

// What a scene asking for lattice.refine lacks or conflicts with (empty: nothing).
std::string refine_conflict(const Scene& s) {
  const LatticeSpec& l = s.lattice;
  const std::string level = std::to_string(l.refine.level);
  if (l.refine.level <= l.level)
    return "lattice.refine.level " + level + " is not finer than lattice.level " + std::to_string(l.level);
  // 8 fine cells to a coarse edge is the most measured to hold (16, level 3 refined to 7, diverged on cube_press)
  if (l.refine.level > l.level + 3)
    return "lattice.refine.level " + level + " is more than 3 levels finer than lattice.level " + std::to_string(l.level) +
           " (a coarse cell of more than 8 x 8 x 8 fine ones; raise lattice.level)";
  if (l.refine.level > s.grid_levels)
    return "lattice.refine.level " + level + " is deeper than grid.levels " + std::to_string(s.grid_levels);
  if (!l.material.enabled)
    return "lattice.refine needs a \"material\" object (each cell's springs and volume or Neo-Hookean term are "
           "calibrated at its own size)";
  if (l.integrator != IntegratorKind::kImplicitEuler)
    return std::string("lattice.refine needs lattice.integrator 'implicit_euler' (the solver that holds the hanging "
                       "nodes on their coarse faces); the scene asks for '") + integrator_name(l.integrator) + "'";
  if (s.mode == InteractionMode::kCut) return "lattice.refine is not supported with interaction.mode 'cut'";
  return {};
}

// The top-level "material" object; exclusive with the raw spring, mass and damping keys of "lattice".
void read_material(ObjectReader& top, const Json& lattice_json, Scene* s, std::string* err) {
  if (!top.has("material")) return;
  const Json& mj = top.object("material");
  ObjectReader r(mj, "material.", err);
  // the surface's friction against the tool is the material's too; an object of friction alone leaves the lattice
  // to its raw keys
  r.number("static_friction", &s->static_friction, 0.0, 10.0);
  r.number("dynamic_friction", &s->dynamic_friction, 0.0, 10.0);
  bool mechanical = false;
  for (const char* key : {"young_modulus_Pa", "poisson_ratio", "density_kg_per_m3", "stiffness_damping_s", "model"})
    mechanical = mechanical || (mj.is_object() && mj.contains(key));
  if (!mechanical) {
    r.finish();
    return;
  }
  MaterialSpec& m = s->lattice.material;
  m.enabled = true;
  for (const char* key : {"young_modulus_Pa", "poisson_ratio", "density_kg_per_m3"}) r.require(key);
  r.number("young_modulus_Pa", &m.young_modulus_Pa, 1.0, 1e12);
  r.number("poisson_ratio", &m.poisson_ratio, -0.999, 0.4999);
  r.number("density_kg_per_m3", &m.density_kg_per_m3, 1.0, 1e5);
  r.number("stiffness_damping_s", &m.stiffness_damping_s, 0.0, 10.0);
  r.name("model", &m.model);
  if (err->empty() && m.model != MaterialModel::kSprings && (m.poisson_ratio < 0.0 || m.poisson_ratio > 0.49))
    r.fail(r.path("poisson_ratio"), std::to_string(m.poisson_ratio) + " is outside [0, 0.49], the range material.model '" +
                                    name_of(m.model) + "' represents");
  r.finish();
  std::string raw;
  for (const char* key : {"node_mass_kg", "stiffness_N_per_m", "damping_Ns_per_m"})
    if (lattice_json.is_object() && lattice_json.contains(key)) raw += (raw.empty() ? "lattice." : ", lattice.") + std::string(key);
  if (err->empty() && !raw.empty())
    r.fail("material", "is exclusive with " + raw + ": give the object in physical units or the raw per-spring/per-node keys, not both");
}

void read_device(ObjectReader& top, Scene* s, std::string* err) {
  ObjectReader r(top.object("device"), "device.", err);
  DeviceSetup& d = s->device;
  r.name("driver", &d.driver);
  r.string("link", &d.link);
  r.number("watchdog_ms", &d.watchdog_ms, 0.1, 10000.0);
  r.number("browser_send_ms", &d.browser_send_ms, 4.0, 100.0);
  r.number("browser_stall_ms", &d.browser_stall_ms, 20.0, 10000.0);
  if (err->empty() && d.browser_stall_ms < 3.0 * d.browser_send_ms)
    r.fail("device.browser_stall_ms", fmt_num(d.browser_stall_ms) + " ms is less than three of the page's sends (" +
                                          "device.browser_send_ms " + fmt_num(d.browser_send_ms) +
                                          " ms): a page that steers would be taken for silent");
  r.number("max_speed_m_per_s", &d.max_speed_m_per_s, 0.01, 1000.0);
  r.number("max_force_N", &d.max_force_N, 0.0, 100.0);
  r.number("coupling_N_per_m", &d.coupling_N_per_m, 0.0, 1e5);
  r.number("coupling_damping_Ns_per_m", &d.coupling_damping_Ns_per_m, 0.0, 1e3);
  r.number("tool_radius_m", &d.tool_radius_m, 1e-5, 1.0);
  const int shape = r.choice("tool_shape", {"point", "sphere"});
  if (shape >= 0) d.sphere_tool = shape == 1;
  const int contact = r.choice("contact", {"prescribed", "solved"});
  if (contact >= 0) d.solved_contact = contact == 1;
  r.number("workspace_half_m", &d.workspace_half_m, 1e-3, 100.0);
  r.number("max_stiffness_N_per_m", &d.max_stiffness_N_per_m, 1.0, 1e5);
  r.number("damping_Ns_per_m", &d.damping_Ns_per_m, 0.0, 1e3);
  r.boolean("passivity", &d.passivity);
  r.number("ramp_s", &d.ramp_s, 0.0, 10.0);
  r.number("jump_limit_N_per_tick", &d.jump_limit_N_per_tick, 0.0, 100.0);
  r.number("force_shading_deg", &d.force_shading_deg, 0.0, 180.0);
  r.range("browser_stiffness_range", &d.browser_stiffness_lo, &d.browser_stiffness_hi, 1e-3, 1e3);
  if (err->empty() && !(d.browser_stiffness_lo <= 1.0 && d.browser_stiffness_hi >= 1.0))
    r.fail(r.path("browser_stiffness_range"), "[" + fmt_num(d.browser_stiffness_lo) + ", " +
                                                 fmt_num(d.browser_stiffness_hi) +
                                                 "] must hold 1 (the scene's own stiffness, where a run starts)");
  r.range("browser_tool_radius_range_m", &d.browser_radius_lo_m, &d.browser_radius_hi_m, 1e-5, 1.0);
  if (err->empty() && d.browser_radius_hi_m > 0.0 &&
      !(d.tool_radius_m >= d.browser_radius_lo_m && d.tool_radius_m <= d.browser_radius_hi_m))
    r.fail(r.path("browser_tool_radius_range_m"), "[" + fmt_num(d.browser_radius_lo_m) + ", " +
                                                       fmt_num(d.browser_radius_hi_m) + "] must hold device.tool_radius_m " +
                                                       fmt_num(d.tool_radius_m) + " (where a run starts)");
  r.finish();

  ObjectReader h(top.object("hand"), "hand.", err);
  h.number("mass_kg", &s->hand.mass_kg, 1e-4, 100.0);
  h.number("stiffness_N_per_m", &s->hand.stiffness_N_per_m, 0.0, 1e6);
  h.number("damping_Ns_per_m", &s->hand.damping_Ns_per_m, 0.0, 1e5);
  h.finish();
}

void read_trajectory(ObjectReader& top, Scene* s, std::string* err) {
  top.require("trajectory");
  const Json* t = top.take("trajectory");
  if (!t) return;
  if (!t->is_array() || t->empty()) return top.fail("trajectory", "must be a non-empty array of keyframes");
  // (more than kMaxKeyframes were refused while parsing, before they were kept)
  for (std::size_t i = 0; i < t->size() && err->empty(); ++i) {
    const std::string p = "trajectory[" + std::to_string(i) + "].";
    ObjectReader r((*t)[i], p, err);
    Keyframe k;
    r.require("t_s");
    if (!r.has("pos_rel")) r.require("pos_m");
    else if (r.has("pos_m")) r.fail(p + "pos_rel", "and pos_m are exclusive");
    r.number("t_s", &k.t_s, 0.0, 1e6);
    r.vec3("pos_m", &k.pos_m, -100.0, 100.0);
    if (r.has("pos_rel")) r.vec3("pos_rel", &k.pos_rel.emplace(), -10.0, 10.0);
    r.boolean("surface", &k.surface);
    r.number("depth_m", &k.depth_m, -1.0, 1.0);
    if (err->empty() && r.has("depth_m") && !k.surface) r.fail(p + "depth_m", "needs \"surface\": true");
    r.boolean("button", &k.button);
    if (const Json* q = r.take("orientation_wxyz")) {
      // every element must be a number: a string or null is an error, not a zero
      Eigen::Vector4d wxyz = Eigen::Vector4d::Zero();
      const bool four_numbers = q->is_array() && q->size() == 4 &&
                                std::all_of(q->begin(), q->end(), [](const Json& e) { return e.is_number(); });
      for (int c = 0; c < 4 && four_numbers; ++c) wxyz[c] = (*q)[c].get<double>();
      if (!(wxyz.allFinite() && wxyz.norm() > 1e-9))
        r.fail(p + "orientation_wxyz", "must be an array of 4 finite numbers, not all zero (w, x, y, z)");
      else k.orientation = Quat(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized();
    }
    r.finish();
    if (err->empty() && !s->trajectory.empty() && k.t_s <= s->trajectory.back().t_s)
      r.fail(p + "t_s", fmt_num(k.t_s) + " must be later than the previous keyframe");
    s->trajectory.push_back(k);
  }
}

void read_render(ObjectReader& top, Scene* s, std::string* err) {
  ObjectReader r(top.object("render"), "render.", err);
  r.integer("width", &s->render.width, 16, 8192);
  r.integer("height", &s->render.height, 16, 8192);
  r.name("style", &s->render.style);
  r.name("backend", &s->render.backend);
  r.number("wire_min_edge_px", &s->render.wire_min_edge_px, 0.0, 1000.0);
  r.number("lod_min_edge_px", &s->render.lod_min_edge_px, 0.0, 100.0);
  r.vec3("view_from", &s->render.view_from, -1e3, 1e3);
  if (err->empty() && r.has("view_from") && !(s->render.view_from.norm() > 1e-6))
    r.fail("render.view_from", "must be a direction (not zero): from the model toward the camera");
  r.vec3("look_at_m", &s->render.look_at_m, -1e3, 1e3);
  r.number("frame_radius_m", &s->render.frame_radius_m, 1e-4, 1e3);
  r.name("color", &s->render.color);
  r.number("color_range_m", &s->render.color_range_m, 0.0, 100.0);
  r.number("strain_range", &s->render.strain_range, 0.0, 100.0);
  r.boolean("force_arrow", &s->render.force_arrow);
  r.boolean("legend", &s->render.legend);
  r.boolean("floor", &s->render.floor);
  r.boolean("force_trace", &s->render.force_trace);
  if (r.has_string("antialias")) {
    const int c = r.choice("antialias", {"edges", "none"});
    if (c >= 0) s->render.antialias = c == 0 ? kAntialiasEdges : 0;
  } else {
    r.integer("antialias", &s->render.antialias, 0, 8);
    if (err->empty() && r.has("antialias") && (s->render.antialias & (s->render.antialias - 1)) != 0)
      r.fail("render.antialias", std::to_string(s->render.antialias) +
                                     " samples a pixel: give \"edges\" (the default), \"none\" (or 0), 2, 4 or 8");
  }
  if (err->empty() && r.has("look_at_m") != r.has("frame_radius_m"))
    r.fail(r.has("look_at_m") ? "render.look_at_m" : "render.frame_radius_m",
           "needs render.look_at_m and render.frame_radius_m together (the sphere the camera frames)");
  r.finish();
  const int64_t pixels = int64_t{s->render.width} * s->render.height;
  if (err->empty() && pixels > kMaxImagePixels)
    r.fail("render", std::to_string(s->render.width) + " x " + std::to_string(s->render.height) + " = " +
                         std::to_string(pixels) + " pixels, more than the limit of " + std::to_string(kMaxImagePixels));
}

constexpr std::size_t kMaxNameLength = 64;

// The name itself when it is a safe file name (A-Z a-z 0-9 . _ -, not starting with '.', at most
// kMaxNameLength); otherwise a cleaned copy: other characters become '_', a leading '.' gets "scene" before it.
std::string safe_name(const std::string& name) {
  std::string out;
  for (char c : name.substr(0, kMaxNameLength))
    out += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-') ? c : '_';
  if (out.empty() || out.front() == '.') out = "scene" + out;
  return out.substr(0, kMaxNameLength);
}


}  // namespace

std::string scene_conflict(const Scene& s) {
  if (s.lattice.level > s.grid_levels)
    return "lattice.level " + std::to_string(s.lattice.level) + " is deeper than grid.levels " + std::to_string(s.grid_levels);
  if (s.device.solved_contact && s.mode != InteractionMode::kTouch)
    return std::string("device.contact: 'solved' is for a touch; interaction.mode is '") + mode_name(s.mode) + "'";
  if (s.device.sphere_tool && s.mode != InteractionMode::kTouch)
    return std::string("device.tool_shape: 'sphere' is a touch tool; interaction.mode is '") + mode_name(s.mode) + "'";
  if (s.dynamic_friction > s.static_friction)
    return "material.dynamic_friction " + fmt_num(s.dynamic_friction) + " exceeds material.static_friction " +
           fmt_num(s.static_friction) + " (sliding friction is at most sticking friction)";
  // the volume term acts on whole cells: the local/global solver's constant matrix does not hold it, and a cut
  // (which removes springs) would leave it holding the cut cells together
  if (s.lattice.material.enabled && s.lattice.material.model != MaterialModel::kSprings) {
    const std::string model = name_of(s.lattice.material.model);
    if (s.lattice.integrator == IntegratorKind::kLocalGlobal)
      return "material.model: '" + model + "' is not supported by lattice.integrator 'local_global' (its prefactored "
             "matrix holds springs only); use implicit_euler, symplectic_euler, explicit_euler or rk4";
    if (s.mode == InteractionMode::kCut)
      return "material.model: '" + model + "' is not supported with interaction.mode 'cut' (the cells' term would "
             "hold the cut together); use material.model 'springs'";
  }
  if (s.lattice.refine.level > 0)
    if (std::string why = refine_conflict(s); !why.empty()) return why;
  if (colors_by_strain(s) && s.mode == InteractionMode::kCut) return kStrainInCut;
  return "";
}

Result<Scene> parse_scene(const std::string& json_text, const std::string& path) {
  const std::string who = "scene '" + path + "': ";
  Result<Json> parsed = parse_scene_json(json_text);
  if (!parsed) return make_error(who, parsed.error().message);
  const Json& j = parsed.value();
  Scene s;
  s.path = path;
  std::string err;
  ObjectReader top(j, "", &err);
  top.string("name", &s.name);
  // the name becomes a folder under out/: a plain file name, never a path
  if (err.empty() && !s.name.empty() && safe_name(s.name) != s.name)
    top.fail("name", std::string("'").append(printable_scene_text(s.name)).append("' must be 1..").append(
                         std::to_string(kMaxNameLength)).append(" characters of A-Z a-z 0-9 . _ - and not start with '.'"));
  read_mesh(top, &s, &err);
  const Json& grid = top.object("grid");
  if (!grid.is_null()) {
    ObjectReader g(grid, "grid.", &err);
    g.integer("levels", &s.grid_levels, 1, kMaxGridLevels);
    g.finish();
  }
  read_lattice(top, &s, &err);
  read_material(top, j.is_object() && j.contains("lattice") ? j.at("lattice") : Json(), &s, &err);
  read_device(top, &s, &err);
  const Json& inter = top.object("interaction");
  if (!inter.is_null()) {
    ObjectReader r(inter, "interaction.", &err);
    r.name("mode", &s.mode);
    r.number("grab_radius_m", &s.grab_radius_m, 0.0, 10.0);
    r.number("blade_length_m", &s.blade_length_m, 1e-4, 10.0);
    r.number("blade_width_m", &s.blade_width_m, 0.0, 0.01);
    r.number("cut_resistance_Ns_per_m", &s.cut_resistance_Ns_per_m, 0.0, 1e4);
    // friction's old place: read, with a warning (and refused beside the new one, which would be ambiguous)
    for (const char* key : {"static_friction", "dynamic_friction"}) {
      if (!r.has(key)) continue;
      const Json& mj = top.object("material");
      if (mj.is_object() && mj.contains(key)) {
        r.fail(r.path(key), std::string("given twice, here and as material.") + key + " (keep that one)");
        continue;
      }
      r.number(key, std::string(key) == "static_friction" ? &s.static_friction : &s.dynamic_friction, 0.0, 10.0);
      s.warnings.push_back(std::string("interaction.") + key + " is read as material." + key +
                           ", where friction is set now: move it there");
    }
    r.finish();
  }
  const Json& servo = top.object("servo");
  if (!servo.is_null()) {
    ObjectReader r(servo, "servo.", &err);
    r.number("rate_hz", &s.rates.servo_hz, kMinServoRate_hz, kMaxServoRate_hz);
    r.finish();
  }
  read_trajectory(top, &s, &err);
  read_render(top, &s, &err);
  top.name("run_mode", &s.run_mode);
  top.number("duration_s", &s.duration_s, s.rates.frame_period_s(), 3600.0);
  top.finish();
  if (err.empty()) err = scene_conflict(s);
  if (!err.empty()) return make_error(who, err);
  if (s.name.empty()) s.name = safe_name(std::filesystem::path(path).stem().string());
  // a relative mesh path is relative to the scene file's folder
  if (!s.mesh.file.empty() && std::filesystem::path(s.mesh.file).is_relative())
    s.mesh.file = (std::filesystem::path(path).parent_path() / s.mesh.file).lexically_normal().string();
  return s;
}

Result<Scene> load_scene(const std::string& path) {
  // only a regular file of bounded size is read: not a device, a FIFO or a 500 MB array
  auto text = read_input_file(path, "scene", kMaxSceneFileBytes);
  if (!text) return text.error();
  return parse_scene(text.value(), path);
}

const char* integrator_name(IntegratorKind kind) { return name_of(kind); }

bool integrator_from_name(const std::string& name, IntegratorKind* kind) {
  const auto k = from_name<IntegratorKind>(name);
  if (k) *kind = *k;
  return k.has_value();
}

const char* mode_name(InteractionMode mode) { return name_of(mode); }

void report_scene_warnings(const Scene& scene, std::FILE* to) {
  for (const std::string& w : scene.warnings)
    std::fprintf(to, "warning: scene '%s': %s\n", scene.path.c_str(), w.c_str());
}

}  // namespace palpate
