#include "tools/commands/tool_cli.h"

#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "core/rates.h"
#include "core/result.h"
#include "tools/commands/info_command.h"
#include "tools/commands/scene_command.h"
#include "tools/commands/video_command.h"

namespace palpate {
namespace {

// A command-line value the parser let through but that does not make sense: one line, exit 2.
int usage_error(const Error& e) {
  std::fprintf(stderr, "palpate: %s\n", e.message.c_str());
  return 2;
}

// `palpate video`'s options, as parsed.
struct VideoArgs {
  std::string folder, out;
  int fps = Rates{}.video_fps();
};

// `palpate info`'s options, as parsed.
struct InfoArgs {
  std::string mesh;
  int levels = 5;
  bool json = false;
};

// `palpate scene`'s options, as parsed.
struct SceneArgs {
  SceneRequest request;
  std::string out, mode = "touch", at, from, up, tool = "point", contact = "prescribed";
};

const std::map<std::string, InteractionMode>& scene_modes() {
  static const std::map<std::string, InteractionMode> modes{
      {"touch", InteractionMode::kTouch}, {"pull", InteractionMode::kPull}, {"cut", InteractionMode::kCut}};
  return modes;
}

int run_video(const VideoArgs& a) {
  auto made = make_recording_video(a.folder, a.out, a.fps);
  if (!made) {
    std::fprintf(stderr, "palpate: %s\n", made.error().message.c_str());
    return 1;
  }
  const auto& m = made.value();
  std::printf("video    %s (%lld frames, %s, %lld bytes)\n", m.path.c_str(), static_cast<long long>(m.frames),
              m.encoder.c_str(), static_cast<long long>(m.bytes));
  return 0;
}

int run_scene_command(SceneArgs& a) {
  SceneRequest& srq = a.request;
  srq.mode = scene_modes().at(a.mode);
  if (!a.up.empty()) srq.up_axis = a.up[0];
  srq.sphere_tool = a.tool == "sphere";
  srq.solved_contact = a.contact == "solved";
  if (!a.at.empty()) {
    auto p = parse_point("--at", a.at);
    if (!p) return usage_error(p.error());
    srq.at_raw = p.value();
  }
  if (!a.from.empty()) {
    auto d = parse_direction("--from", a.from);
    if (!d) return usage_error(d.error());
    srq.from = d.value();
  }
  return run_scene(srq, a.out);
}

}  // namespace

Subcommand add_video_command(CLI::App& app) {
  auto a = std::make_shared<VideoArgs>();
  auto* c = app.add_subcommand("video", "Make the MP4 (H.264, yuv420p) of a recording from its frames/frame_*.png");
  c->add_option("folder", a->folder, "Recording folder (holds frames/ and summary.json)")->required();
  c->add_option("--out,-o", a->out, "MP4 to write (default: FOLDER/recording.mp4)");
  c->add_option("--fps", a->fps, "Frames per second")->check(CLI::Range(1, 1000))->capture_default_str();
  return {c, [a] { return run_video(*a); }};
}

Subcommand add_info_command(CLI::App& app) {
  auto a = std::make_shared<InfoArgs>();
  auto* c = app.add_subcommand("info", "Mesh counts, box and grid hierarchy per level");
  c->add_option("mesh", a->mesh, "Mesh file (OBJ, PLY, STL, OFF, ...)")->required();
  c->add_option("--levels,-k", a->levels, "Grid levels (1..8)")->check(CLI::Range(1, 8));
  c->add_flag("--json", a->json, "Print JSON");
  return {c, [a] { return run_info(a->mesh, a->levels, a->json); }};
}

Subcommand add_scene_command(CLI::App& app) {
  auto a = std::make_shared<SceneArgs>();
  auto* c = app.add_subcommand("scene", "Write a touch, pull or cut scene that works on any mesh");
  c->add_option("mesh", a->request.mesh_path, "Mesh file (anything `palpate info` reads)")->required();
  c->add_option("--mode", a->mode, "touch (press), pull (grab and pull out) or cut (draw a blade across)")
      ->check(CLI::IsMember(scene_modes()))->capture_default_str();
  c->add_option("--out,-o", a->out, "Scene file to write (default: <mesh name>_<mode>.json here)");
  auto* at = c->add_option("--at", a->at, "Work at the surface point nearest X,Y,Z (the mesh file's own "
                           "coordinates, as `palpate info` prints its box)");
  c->add_option("--from", a->from, "Come in from this side, +x|-x|+y|-y|+z|-z (world, +z = up): the first surface "
                "a ray from there through the model's centre meets (default +z)")->excludes(at);
  c->add_option("--depth-mm", a->request.depth_mm, "Press / pull / cut depth in mm (default 10, pull 15)")
      ->check(CLI::Range(0.5, 50.0));
  c->add_option("--level", a->request.level, "Lattice level (default: sized to the model)")->check(CLI::Range(1, 8));
  c->add_option("--up", a->up, "The file's up axis (default: guessed from the model's extent)")
      ->check(CLI::IsMember({"x", "y", "z"}));
  auto* young = c->add_option("--young-modulus", a->request.young_modulus_Pa, "A material in physical units: E in Pa "
                              "(soft tissue 1e3-1e5, silicone 1e5-1e6); touch gets material.model volumetric, pull "
                              "neo_hookean, cut springs (default: the raw springs of the shipped bunny scenes)")
                    ->check(CLI::Range(1.0, 1e9));
  c->add_option("--poisson", a->request.poisson_ratio, "Its Poisson ratio, 0-0.49")
      ->check(CLI::Range(0.0, 0.49))->needs(young)->capture_default_str();
  c->add_option("--density", a->request.density_kg_per_m3, "Its density in kg/m^3")
      ->check(CLI::Range(1.0, 1e5))->needs(young)->capture_default_str();
  c->add_option("--tool", a->tool, "The tool's tip: point or sphere (sphere: touch only)")
      ->check(CLI::IsMember({"point", "sphere"}))->capture_default_str();
  c->add_option("--tool-radius-mm", a->request.tool_radius_mm, "The tool's radius in mm (a sphere's contact radius)")
      ->check(CLI::Range(0.5, 20.0))->capture_default_str();
  c->add_option("--contact", a->contact, "prescribed (a point load, or a sphere's Hertz pressure) or solved (found "
                "where the surface, deformed by the push, meets the tool's tip; touch only)")
      ->check(CLI::IsMember({"prescribed", "solved"}))->capture_default_str();
  return {c, [a] { return run_scene_command(*a); }};
}

}  // namespace palpate
