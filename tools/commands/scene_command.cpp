#include "tools/commands/scene_command.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/aabb.h"
#include "core/atomic_file.h"
#include "core/mesh_io.h"
#include "runtime/session/model.h"
#include "tools/commands/scene_material.h"
#include "tools/commands/scene_target.h"
#include "tools/commands/scene_trajectory.h"
#include "tools/commands/subcommand.h"
#include "runtime/session/surface_queries.h"

namespace palpate {
namespace fs = std::filesystem;
namespace {

constexpr double kSize_m = 0.1;          // largest side after normalisation, as the shipped scenes
constexpr double kClearance_m = 0.03;    // the tool starts and ends this far out of the surface
constexpr double kCutMaxEdgeCells = 2.0;  // a cut scene's longest edge, in lattice cells, after its subdivisions
constexpr std::size_t kCutSubdivideMaxTriangles = 20'000;  // no subdivision past this many triangles
constexpr double kShortRun = 0.25;       // a cut's incision shorter than this fraction of the model is short ...
constexpr double kLongerRun = 1.5;       // ... and another way in is taken when its stroke is this much longer
constexpr int kWidthPx = 640, kHeightPx = 480;  // render.width, render.height
constexpr double kSheetBladeWidth_m = 0.002;
constexpr std::size_t kFramedMaxTriangles = 100'000;  // a cut's closer view: meshes up to this many triangles ...
constexpr double kHardlySeenPx = 50.0;   // ... or any whose incision is shorter than this in the whole view  // a cut sheet's slit: its sides this far apart
constexpr double kSceneWireMinEdgePx = 4.0;  // render.wire_min_edge_px: no wireframe over a finer mesh (below)

std::string mm3(const Vec3& p_m) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.1f, %.1f, %.1f] mm", 1e3 * p_m.x(), 1e3 * p_m.y(), 1e3 * p_m.z());
  return buf;
}

std::string dir_name(const Vec3& d) {
  for (int a = 0; a < 3; ++a)
    if (std::abs(std::abs(d[a]) - 1.0) < 1e-9) return std::string(d[a] > 0 ? "+" : "-") + static_cast<char>('x' + a);
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.2f, %.2f, %.2f)", d.x(), d.y(), d.z());
  return buf;
}

// most characters of a scene's name (as the scene reader allows)
constexpr std::size_t kMaxSceneName = 64;

// '<stem>_<mode>' made a name the scene reader takes: A-Z a-z 0-9 . _ - only (others become '_'), not starting with
// '.', the stem shortened so the whole fits kMaxSceneName
std::string scene_name(const std::string& stem, const std::string& mode) {
  std::string out;
  for (char c : stem) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-') ? c : '_';
  if (out.empty() || out.front() == '.') out = "model" + out;
  const std::string suffix = "_" + mode;
  if (out.size() + suffix.size() > kMaxSceneName) out.resize(kMaxSceneName - suffix.size());
  return out + suffix;
}

// one line per value: {"a": 1, "b": [1, 2]}
std::string inline_json(const nlohmann::ordered_json& v) {
  if (!v.is_object() && !v.is_array()) return v.dump();
  std::string s = v.is_object() ? "{ " : "[";
  bool first = true;
  for (auto it = v.begin(); it != v.end(); ++it) {
    s += first ? "" : ", ";
    if (v.is_object()) s += nlohmann::ordered_json(it.key()).dump() + ": ";
    s += inline_json(it.value());
    first = false;
  }
  return s + (v.is_object() ? " }" : "]");
}

// the layout of the shipped scenes: a section a line, a keyframe a line
std::string scene_text(const nlohmann::ordered_json& j) {
  std::string s = "{\n";
  bool first = true;
  for (auto it = j.begin(); it != j.end(); ++it) {
    s += first ? "" : ",\n";
    s += "  " + nlohmann::ordered_json(it.key()).dump() + ": ";
    if (it.value().is_array() && !it.value().empty() && it.value().front().is_object()) {
      s += "[\n";
      for (std::size_t i = 0; i < it.value().size(); ++i)
        s += "    " + inline_json(it.value()[i]) + (i + 1 < it.value().size() ? ",\n" : "\n");
      s += "  ]";
    } else {
      s += inline_json(it.value());
    }
    first = false;
  }
  return s + "\n}\n";
}

}  // namespace

Result<Vec3> parse_point(const std::string& option, const std::string& text) {
  Vec3 p;
  std::stringstream s(text);
  std::string part;
  int n = 0;
  while (std::getline(s, part, ',')) {
    char* end = nullptr;
    const double x = std::strtod(part.c_str(), &end);
    if (n >= 3 || part.empty() || end == part.c_str() || *end != '\0' || !std::isfinite(x))
      return make_error(option, " '", text, "': expected three numbers X,Y,Z");
    p[n++] = x;
  }
  if (n != 3) return make_error(option, " '", text, "': expected three numbers X,Y,Z");
  return p;
}

Result<Vec3> parse_direction(const std::string& option, const std::string& text) {
  std::string t = text;
  double sign = 1.0;
  if (!t.empty() && (t[0] == '+' || t[0] == '-')) {
    sign = t[0] == '-' ? -1.0 : 1.0;
    t = t.substr(1);
  }
  if (t.size() != 1 || t[0] < 'x' || t[0] > 'z')
    return make_error(option, " '", text, "': expected an axis with a sign: +x, -x, +y, -y, +z or -z");
  Vec3 d = Vec3::Zero();
  d[t[0] - 'x'] = sign;
  return d;
}

Result<GeneratedScene> generate_scene(const SceneRequest& rq) {
  GeneratedScene g;
  // the command line's range check lets NaN through: every number is checked here again
  if (!std::isfinite(rq.depth_mm) || rq.depth_mm < 0.0 || (rq.depth_mm > 0.0 && (rq.depth_mm < 0.5 || rq.depth_mm > 50.0)))
    return make_error("--depth-mm ", std::to_string(rq.depth_mm), ": not a number in [0.5, 50]");
  if (rq.level < 0 || rq.level > 8) return make_error("--level ", std::to_string(rq.level), ": not in [1, 8]");
  if (rq.at_raw && !rq.at_raw->allFinite()) return make_error("--at: not three finite numbers");
  if (rq.from && !(rq.from->allFinite() && std::abs(rq.from->norm() - 1.0) < 1e-9))
    return make_error("--from: not a unit direction");
  if (auto st = check_scene_material(rq.young_modulus_Pa, rq.poisson_ratio, rq.density_kg_per_m3); !st)
    return st.error();
  if (!std::isfinite(rq.tool_radius_mm) || rq.tool_radius_mm < 0.5 || rq.tool_radius_mm > 20.0)
    return make_error("--tool-radius-mm ", std::to_string(rq.tool_radius_mm), ": not a number in [0.5, 20]");
  // a scene `palpate record` would refuse is never written: the sphere is a touch tool
  if (rq.sphere_tool && rq.mode != InteractionMode::kTouch)
    return make_error("--tool sphere: the sphere is a touch tool; --mode is '", mode_name(rq.mode),
                      "' (touch only; pull and cut take the point tool)");
  if (rq.solved_contact && rq.mode != InteractionMode::kTouch)
    return make_error("--contact solved: the contact is solved under a pressing tool; --mode is '",
                      mode_name(rq.mode), "' (touch only)");
  auto raw_r = load_mesh(rq.mesh_path);
  if (!raw_r) return raw_r.error();
  const TriMesh& raw = raw_r.value();
  const Aabb raw_box = Aabb::of(raw.vertices_m);

  // up axis, then levels sized to the model's thinnest side and triangle count
  std::string why;
  const char up = rq.up_axis ? rq.up_axis : guess_up_axis(raw_box, rq.mesh_path, &why);
  g.notes.push_back(std::string("up axis ") + up + (rq.up_axis ? " (--up)" : " (guessed: " + why + "; --up x|y|z to change)"));
  const Vec3 e = raw_box.extent();
  const double thin_m = e.maxCoeff() > 0.0 ? kSize_m * e.minCoeff() / e.maxCoeff() : 0.0;
  // level 5 (16 cells a side) when two of its cells fit across the thinnest side, else 6; cut simulates the whole
  // object, so it stays at 5
  const int max_level = rq.mode == InteractionMode::kCut ? 5 : 6;
  const int level = rq.level > 0 ? rq.level : (thin_m >= 2.0 * kSize_m / 16.0 ? 5 : max_level);
  const std::size_t tris = raw.num_triangles();
  const int grid_levels = std::min(8, std::max(level, 5 + (tris > 100'000 ? 1 : 0) + (tris > 400'000 ? 1 : 0)));
  char buf[320];
  std::snprintf(buf, sizeof buf, "lattice level %d%s (thinnest side %.0f mm of %.0f), grid levels %d (%zu triangles)",
                level, rq.level > 0 ? " (--level)" : "", 1e3 * thin_m, 1e3 * kSize_m, grid_levels, tris);
  g.notes.push_back(buf);

  // a cut draws its incision with the triangles it splits: a face much larger than the lattice's cells (a CAD
  // part's, a coarse box's) is split along its edges only and the blade's path across it shows nothing, so a cut
  // scene subdivides the mesh (same shape) until its longest edge is two cells or less, within a triangle budget
  int subdivisions = 0;
  if (rq.mode == InteractionMode::kCut && e.maxCoeff() > 0.0) {
    double longest = 0.0;
    for (const auto& t : raw.triangles)
      for (int c = 0; c < 3; ++c)
        longest = std::max(longest, (raw.vertices_m[static_cast<std::size_t>(t[c])] -
                                     raw.vertices_m[static_cast<std::size_t>(t[(c + 1) % 3])]).norm());
    const double longest_m = kSize_m * longest / e.maxCoeff(), cell_m = kSize_m / static_cast<double>(1 << (level - 1));
    while (subdivisions < 5 && longest_m / static_cast<double>(1 << subdivisions) > kCutMaxEdgeCells * cell_m &&
           tris << (2 * (subdivisions + 1)) <= kCutSubdivideMaxTriangles)
      ++subdivisions;
    if (subdivisions > 0) {
      std::snprintf(buf, sizeof buf, "mesh.subdivisions %d (cut: the longest edge, %.0f mm, down to %.1f mm of %.1f mm "
                    "cells; %zu triangles)", subdivisions, 1e3 * longest_m, 1e3 * longest_m / (1 << subdivisions),
                    1e3 * cell_m, tris << (2 * subdivisions));
      g.notes.push_back(buf);
    }
  }

  Scene spec;
  spec.mesh.file = rq.mesh_path;
  spec.mesh.size_m = kSize_m;
  spec.mesh.up_axis = up;
  spec.mesh.subdivisions = subdivisions;
  spec.grid_levels = grid_levels;
  spec.lattice.level = level;
  auto model_r = load_model(spec);
  if (!model_r) return model_r.error();
  const Model& model = model_r.value();
  if (!model.orientation.notice().empty()) g.notes.push_back(model.orientation.notice());
  const Aabb box = Aabb::of(model.rest.vertices_m);

  // the surface point and the direction the tool comes in along (a cut: other points it may enter at, below)
  double clearance_m = kClearance_m;
  std::vector<SurfaceHit> more;
  if (rq.at_raw) {
    const Vec3 at_m = model.normalization.scale * file_to_world_axes(*rq.at_raw, up) + model.normalization.offset_m;
    const auto hit = nearest_surface_point(model, at_m);
    if (!hit) return make_error("mesh '", rq.mesh_path, "': no surface near --at");
    g.surface_point_m = hit->point_m;
    g.surface_normal = hit->normal;
    g.approach = -hit->normal;  // into the face from its front, as the servo's touch test expects
    // shorten the way in when other parts of the model stand in front of the face
    const auto block = first_ray_hit(model, hit->point_m + 1e-6 * hit->normal, hit->normal, kClearance_m, false);
    if (block) clearance_m = std::max(0.5 * block->distance_m, 2e-3);
    if (!feelable(model, *hit, kGrabRadius_m))
      g.notes.push_back("warning: the face at --at is large among many small ones near it; the tool may not feel it");
    g.notes.push_back("at " + mm3(g.surface_point_m) + ", the surface point nearest --at " + mm3(at_m) + " (" +
                      std::to_string(static_cast<int>(std::lround(1e3 * hit->distance_m))) + " mm away), approached along " +
                      dir_name(g.approach));
  } else {
    // from above unless told; a model with no face turned up (an open shell facing down) is met from another side
    std::vector<Vec3> sides{rq.from.value_or(Vec3::UnitZ())};
    if (!rq.from)
      for (const Vec3& s : {Vec3(Vec3::UnitX()), Vec3(-Vec3::UnitX()), Vec3(Vec3::UnitY()), Vec3(-Vec3::UnitY()),
                            Vec3(-Vec3::UnitZ())})
        sides.push_back(s);
    bool offset = false;
    std::optional<SurfaceHit> hit;
    more.clear();
    Vec3 from = sides.front();
    for (const Vec3& s : sides) {
      hit = surface_from(model, box, s, kGrabRadius_m, &offset, rq.mode == InteractionMode::kCut ? &more : nullptr);
      if (hit) {
        from = s;
        break;
      }
    }
    if (!hit)
      return make_error("mesh '", rq.mesh_path, "': ", rq.from ? "--from " + dir_name(from) + ": no face of the model faces " +
                        dir_name(from) : std::string("no face of the model faces outward on any side"),
                        " where the tool can feel it (an open shell facing away from every side?)");
    if (from != sides.front())
      g.notes.push_back("no face turned to +z can be touched from above: coming in from " + dir_name(from) + " instead");
    g.surface_point_m = hit->point_m;
    g.surface_normal = hit->normal;
    g.approach = -from;
    const auto any = first_ray_hit(model, hit->point_m + 0.2 * from, -from, 0.2, false);
    const bool hidden = any && any->distance_m < 0.2 - 1e-6;
    g.notes.push_back("at " + mm3(g.surface_point_m) + ", the first surface facing " + dir_name(from) + " on a ray from " +
                      dir_name(from) + (offset ? " beside the model's centre (none through it)" : " through the model's centre") +
                      (hidden ? "; a face turned away lies in front of it (an open shell, or a part inside another)" : ""));
  }

  double depth_m = 1e-3 * (rq.depth_mm > 0.0 ? rq.depth_mm : rq.mode == InteractionMode::kPull ? 15.0 : 10.0);
  CutStroke stroke;
  if (rq.mode == InteractionMode::kCut) {
    stroke = choose_cut_stroke(model, box, g.surface_point_m, g.approach, depth_m, clearance_m);
    // a short incision (a thin limb under the point) moves the way in to where a stroke stays on the surface at
    // least half as long again, the longest of those (the nearest the centre on a tie)
    const double first_run_m = stroke.run_m;
    if (first_run_m < kShortRun * box.extent().maxCoeff())
      for (const SurfaceHit& h : more) {
        const CutStroke other = choose_cut_stroke(model, box, h.point_m, g.approach, depth_m, clearance_m);
        if (other.run_m < kLongerRun * first_run_m || other.run_m <= stroke.run_m) continue;
        stroke = other;
        g.surface_point_m = h.point_m;
        g.surface_normal = h.normal;
      }
    if (stroke.run_m > first_run_m) {
      std::snprintf(buf, sizeof buf, "cut: in at %s instead, where the blade's path stays on the surface %.0f mm "
                    "(%.0f mm at the first point)", mm3(g.surface_point_m).c_str(), 1e3 * stroke.run_m, 1e3 * first_run_m);
      g.notes.push_back(buf);
    }
    std::snprintf(buf, sizeof buf, "blade drawn along %s: it crosses the surface over %.0f mm from the point",
                  dir_name(stroke.across).c_str(), 1e3 * stroke.run_m);
    g.notes.push_back(buf);
  }
  const Vec3 P = g.surface_point_m;
  const Vec3 d = g.approach;
  // a press or a pull goes at most half through the body under the point: the default 10 mm pressed a 5 mm plate
  // through (a cut goes in as deep as asked: a thin part is cut through)
  if (rq.mode != InteractionMode::kCut) {
    const double thick_m = thickness_under(model, P, d, box.extent().norm());
    const double bound_m = kDepthOfThickness * thick_m;
    if (std::isfinite(thick_m) && depth_m > bound_m) {
      std::snprintf(buf, sizeof buf, "%s %.1f mm, %s of the body's %.1f mm under the point%s", rq.mode ==
                    InteractionMode::kTouch ? "press" : "pull", 1e3 * (rq.depth_mm > 0.0 ? depth_m : bound_m),
                    rq.depth_mm > 0.0 ? "more than half" : "half", 1e3 * thick_m,
                    rq.depth_mm > 0.0 ? " (warning: --depth-mm as asked)" : " (shallower than the default)");
      g.notes.push_back(buf);
      if (rq.depth_mm == 0.0) depth_m = bound_m;
    }
  }

  nlohmann::ordered_json j;
  const std::string stem = fs::path(rq.mesh_path).stem().string();
  j["name"] = scene_name(stem, mode_name(rq.mode));
  // the mesh path as the scene resolves it: relative to the scene's folder when the mesh is below it
  const fs::path mesh_abs = fs::weakly_canonical(fs::absolute(rq.mesh_path));
  const fs::path dir_abs = fs::weakly_canonical(fs::absolute(rq.scene_dir.empty() ? "." : rq.scene_dir));
  const fs::path rel = mesh_abs.lexically_relative(dir_abs);
  const bool below = !rel.empty() && *rel.begin() != "..";
  j["mesh"] = {{"file", (below ? rel : mesh_abs).string()}, {"size_m", kSize_m}, {"up_axis", std::string(1, up)}};
  if (subdivisions > 0) j["mesh"]["subdivisions"] = subdivisions;
  j["grid"] = {{"levels", grid_levels}};
  // the shipped scenes' materials: soft for touch and pull, stiffer and under gravity for cut
  nlohmann::ordered_json lat;
  lat["level"] = level;
  lat["radius_cells"] = 3;
  if (rq.young_modulus_Pa > 0.0) {
    // a material the user names: its model by what the mode needs (scene_material.h)
    const SceneMaterial m = scene_material(rq.mode, rq.young_modulus_Pa, rq.poisson_ratio, rq.density_kg_per_m3);
    lat["gravity_m_per_s2"] = rq.mode == InteractionMode::kCut ? nlohmann::ordered_json{0, 0, -9.81}
                                                               : nlohmann::ordered_json{0, 0, 0};
    lat["fix_floor"] = true;
    lat["integrator"] = m.integrator;
    j["lattice"] = lat;
    j["material"] = m.json;
    g.notes.push_back(m.note);
  } else if (rq.mode == InteractionMode::kCut) {
    lat["node_mass_kg"] = 0.0002;
    lat["stiffness_N_per_m"] = {{"structural", 100}, {"shear", 50}, {"bend", 25}};
    lat["damping_Ns_per_m"] = 0.05;
    lat["gravity_m_per_s2"] = {0, 0, -9.81};
    lat["fix_floor"] = true;
    lat["integrator"] = "local_global";
  } else {
    lat["node_mass_kg"] = 0.002;
    lat["stiffness_N_per_m"] = {{"structural", 12}, {"shear", 6}, {"bend", 3}};
    lat["damping_Ns_per_m"] = 0.03;
    lat["gravity_m_per_s2"] = {0, 0, 0};
    lat["fix_floor"] = true;
    lat["integrator"] = "symplectic_euler";
  }
  if (rq.young_modulus_Pa <= 0.0) {
    lat["max_substeps"] = 256;
    j["lattice"] = lat;
  }
  j["device"] = {{"driver", "scripted"},         {"max_force_N", 3.3},      {"coupling_N_per_m", 300},
                 {"coupling_damping_Ns_per_m", 0.5}, {"tool_radius_m", 1e-3 * rq.tool_radius_mm}};
  if (rq.sphere_tool) j["device"]["tool_shape"] = "sphere";
  if (rq.solved_contact) j["device"]["contact"] = "solved";
  j["device"]["workspace_half_m"] = 0.2;
  j["hand"] = {{"mass_kg", 0.12}, {"stiffness_N_per_m", 150}, {"damping_Ns_per_m", 6}};

  // a sphere's keys are its centre's: a radius back from the surface, so `depth` is how far the sphere goes in
  const Vec3 tip_m = rq.sphere_tool && rq.mode != InteractionMode::kCut ? Vec3(P - 1e-3 * rq.tool_radius_mm * d) : P;
  const double duration_s = add_trajectory(rq.mode, tip_m, d, clearance_m, depth_m, stroke, box, &j);
  // a sheet with no thickness has no groove to show (nothing under the rim to sink into): its two sides are set
  // apart by the blade's width instead, so the slit opens
  if (rq.mode == InteractionMode::kCut && !std::isfinite(thickness_under(model, P, d, box.extent().norm()))) {
    j["interaction"]["blade_width_m"] = kSheetBladeWidth_m;
    std::snprintf(buf, sizeof buf, "cut: no body under the entry point (a sheet with no thickness): "
                  "interaction.blade_width_m %.1f mm sets the slit's sides apart", 1e3 * kSheetBladeWidth_m);
    g.notes.push_back(buf);
  }
  // a wireframe only where its lines leave the surface visible: 1-px lines over triangles of edge a px cover about
  // 3.5 / a of it (all of it at a 2.6 px median edge, a 50k-triangle scan in this view), and they cost every frame
  j["render"] = {{"width", kWidthPx}, {"height", kHeightPx}, {"style", "both"}, {"backend", "auto"},
                 {"wire_min_edge_px", kSceneWireMinEdgePx}};
  if (rq.mode == InteractionMode::kCut) {
    // a cut is drawn solid: its incision shows as a shaded line, and the wireframe of a subdivided part (the
    // bracket's top: slivers 0.6 mm across, under the median edge the renderer tests) covered it with a moire
    j["render"]["style"] = "solid";
    const Vec3 v = cut_view_from(d, g.surface_normal);
    auto r3 = [](double x) { return std::round(1e3 * x) / 1e3; };
    j["render"]["view_from"] = {r3(v.x()), r3(v.y()), r3(v.z())};
    // the incision's length in the picture, as the blade's keys draw it (the way in, key 2, to the way out, key 3)
    const auto& k = j["trajectory"];
    auto pos = [&](std::size_t i) {
      const auto& p = k[i]["pos_m"];
      return Vec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    };
    const double blade_m = j["interaction"]["blade_length_m"].get<double>();
    const double aspect = static_cast<double>(kWidthPx) / kHeightPx;
    auto seen_px = [&](const Camera& cam) {
      return incision_px(model, cam, kWidthPx, kHeightPx, pos(2), pos(3), d, blade_m);
    };
    const double whole_px = seen_px(Camera::framing(box.min_m, box.max_m, aspect, v));
    // an incision small in the whole model's frame (a limb of a figure) is framed with its surroundings instead, on
    // a mesh whose closer view the layer redraws can afford (a 200k-triangle scan's took 93 against 28 ms and wrote
    // 93 against 98 % of its realtime frames), or where the incision would hardly be seen at all
    const bool affordable = (tris << (2 * subdivisions)) <= kFramedMaxTriangles;
    std::optional<CutFrame> f;
    if (affordable || whole_px < kHardlySeenPx) f = cut_frame(P, d, stroke, depth_m, box);
    if (f) {
      auto um = [](double x_m) { return std::round(x_m * 1e6) / 1e6; };
      j["render"]["look_at_m"] = {um(f->look_at_m.x()), um(f->look_at_m.y()), um(f->look_at_m.z())};
      j["render"]["frame_radius_m"] = um(f->radius_m);
      std::snprintf(buf, sizeof buf, "view: the incision and %.0f mm around it, centred at %s (the model's box is "
                    "%.0f mm across): the incision %.0f px long at 640 x 480 (%.0f px with the whole model framed)",
                    1e3 * f->radius_m, mm3(f->look_at_m).c_str(), 1e3 * box.extent().norm(),
                    seen_px(Camera::framing_part(box.min_m, box.max_m, aspect, v, f->look_at_m, f->radius_m)), whole_px);
    } else {
      std::snprintf(buf, sizeof buf, "view: the whole model: the incision %.0f px long at 640 x 480%s", whole_px,
                    affordable ? "" : " (a closer view of this many triangles would cost realtime frames)");
    }
    g.notes.push_back(buf);
  }
  j["run_mode"] = "lockstep";
  j["duration_s"] = duration_s;
  g.json = std::move(j);
  return g;
}

int run_scene(SceneRequest rq, const std::string& out_path) {
  const std::string out =
      out_path.empty() ? fs::path(rq.mesh_path).stem().string() + "_" + mode_name(rq.mode) + ".json" : out_path;
  rq.scene_dir = fs::path(out).parent_path().string();
  // the scene is never written over the model it is made for
  std::error_code ec;
  if (fs::weakly_canonical(fs::absolute(out), ec) == fs::weakly_canonical(fs::absolute(rq.mesh_path), ec) ||
      (fs::exists(out, ec) && fs::equivalent(out, rq.mesh_path, ec))) {
    std::fprintf(stderr, "palpate: --out '%s' is the mesh file itself: the scene would replace the model it points at\n",
                 out.c_str());
    return 1;
  }
  auto g = generate_scene(rq);
  if (!g) {
    std::fprintf(stderr, "palpate: %s\n", g.error().message.c_str());
    return 1;
  }
  for (const std::string& n : g.value().notes) std::fprintf(stderr, "palpate scene: %s\n", n.c_str());
  // a folder the scene goes in is made, as `record -o` makes its own (`--out out/x.json` in a fresh clone)
  if (const fs::path folder = fs::path(out).parent_path(); !folder.empty() && !fs::is_directory(folder, ec)) {
    fs::create_directories(folder, ec);
    if (ec) {
      std::fprintf(stderr, "palpate: scene '%s': cannot make its folder '%s': %s\n", out.c_str(), folder.c_str(),
                   ec.message().c_str());
      return 1;
    }
  }
  if (auto st = write_file_atomic(out, scene_text(g.value().json), "scene"); !st) {
    std::fprintf(stderr, "palpate: %s\n", st.error().message.c_str());
    return 1;
  }
  std::printf("scene    %s\nrecord   %s record %s\n", out.c_str(), invoked_program().c_str(), out.c_str());
  return 0;
}

}  // namespace palpate
