#include "tools/bench/bench_scale.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <algorithm>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/scene.h"
#include "tools/bench/plot.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {

namespace fs = std::filesystem;

// One recording of one size: its summary and the peak resident memory of the process that made it.
struct ScaleRun {
  int subdivisions = 0;
  bool full_redraw = false;
  nlohmann::json summary;
  double peak_rss_MB = 0.0;
};

// Records in a child process (so ru_maxrss is this run's alone); the child's error, if any, comes back in a file.
Result<ScaleRun> record_in_child(const Scene& base, int subdivisions, bool full_redraw, double duration_s,
                                 const fs::path& work) {
  const std::string tag = std::to_string(subdivisions) + (full_redraw ? "_full" : "_layered");
  const fs::path out = work / tag;
  const fs::path err = work / (tag + ".err");
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) return make_error("bench scale: fork failed");
  if (pid == 0) {
    Scene s = base;
    s.mesh.subdivisions = subdivisions;
    RecordOptions opt;
    opt.out_dir = out.string();
    opt.quiet = true;
    opt.duration_s = duration_s;
    opt.full_redraw = full_redraw;
    opt.override_mode = true;
    opt.mode = RunMode::kLockstep;
    auto r = record_scene(s, opt);
    if (!r) std::ofstream(err) << r.error().message;
    std::fflush(nullptr);
    ::_exit(r ? 0 : 1);
  }
  int status = 0;
  rusage ru{};
  if (::wait4(pid, &status, 0, &ru) != pid) return make_error("bench scale: wait for the run '", tag, "' failed");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    std::ifstream f(err);
    std::stringstream msg;
    msg << f.rdbuf();
    return make_error("bench scale: run '", tag, "' failed: ",
                      msg.str().empty() ? std::string("killed or crashed (status ") + std::to_string(status) + ")"
                                        : msg.str());
  }
  ScaleRun run;
  run.subdivisions = subdivisions;
  run.full_redraw = full_redraw;
  std::ifstream f(out / "summary.json");
  run.summary = nlohmann::json::parse(f, nullptr, false);
  if (run.summary.is_discarded()) return make_error("bench scale: run '", tag, "' left no readable summary.json");
  run.peak_rss_MB = static_cast<double>(ru.ru_maxrss) / 1024.0;  // Linux: kilobytes
  fs::remove_all(out);  // the frames are not kept: only the figures
  return run;
}

nlohmann::json row_json(const ScaleRun& r) {
  const auto& s = r.summary;
  return {{"subdivisions", r.subdivisions},
          {"full_redraw", r.full_redraw},
          {"triangles", s["model"]["triangles"]},
          {"startup_s", s["model"]["startup_s"]},
          {"peak_rss_MB", r.peak_rss_MB},
          {"sim_ms", s["sim"]["ms"]},
          {"render_ms", s["render"]["ms"]},
          {"png_ms", s["png"]["ms"]},
          {"frames_layered", s["render"]["frames_layered"]},
          // `both` leaves its wireframe out on a mesh finer than the image: rows then draw different things
          {"wire", s["render"].contains("wire") ? s["render"]["wire"] : nlohmann::json(nullptr)},
          // a mesh finer than the image is drawn clustered (render.lod_min_edge_px)
          {"lod", s["render"].contains("lod") ? s["render"]["lod"] : nlohmann::json(nullptr)},
          {"wall_s_per_scene_s", s["wall_s_per_scene_s"]},
          {"state_hash", s.value("state_hash", "")}};
}

std::string table(const std::vector<ScaleRun>& runs) {
  std::ostringstream t;
  char line[256];
  std::snprintf(line, sizeof line, "%-9s %8s %8s %9s %8s %15s %17s %15s %12s %6s\n", "draw", "tris", "drawn",
                "start s", "RSS MB", "sim p50/p99 ms", "render p50/p99 ms", "png p50/p99 ms", "wall s / s", "lines");
  t << line;
  for (const ScaleRun& r : runs) {
    const auto& s = r.summary;
    auto ms = [](const nlohmann::json& m) {
      char b[32];
      std::snprintf(b, sizeof b, "%.1f / %.1f", m["p50"].get<double>(), m["p99"].get<double>());
      return std::string(b);
    };
    // whether the wireframe was drawn (`both` only; "-" for other styles)
    const char* lines = "-";
    if (s["render"].contains("wire")) lines = s["render"]["wire"].value("drawn", false) ? "yes" : "no";
    // the triangles frames are drawn with: the clustered mesh's on a mesh finer than the image
    const long long tris = s["model"]["triangles"].get<long long>();
    long long drawn = tris;
    if (s["render"].contains("lod") && s["render"]["lod"].value("used", false))
      drawn = s["render"]["lod"]["triangles"].get<long long>();
    std::snprintf(line, sizeof line, "%-9s %8lld %8lld %9.2f %8.0f %15s %17s %15s %12.2f %6s\n",
                  r.full_redraw ? "full" : "layered", tris, drawn,
                  s["model"]["startup_s"].get<double>(), r.peak_rss_MB, ms(s["sim"]["ms"]).c_str(),
                  ms(s["render"]["ms"]).c_str(), ms(s["png"]["ms"]).c_str(), s["wall_s_per_scene_s"].get<double>(),
                  lines);
    t << line;
  }
  return t.str();
}

PlotSpec plot(const std::vector<ScaleRun>& runs, const std::string& scene_path, double frame_hz) {
  PlotSpec spec;
  spec.title = "bench scale: ms per frame (median) against triangles";
  spec.what = "palpate bench scale " + scene_path + ": per-frame medians of each recording";
  spec.x_label = "triangles";
  spec.y_label = "ms per frame (median)";
  spec.x_column = "triangles";
  spec.key_outside = true;  // never over a point
  spec.y_column = "ms_per_frame_p50";
  auto series = [](const char* label, const char* colour, int point_type) {
    PlotSeries p;
    p.label = label;
    p.colour = colour;
    p.point_type = point_type;
    p.style = PlotStyle::kLinesPoints;
    p.extra = {{"subdivisions", {}}};
    return p;
  };
  PlotSeries lr = series("render, layered", "#c8281e", 7), fr = series("render, full redraw", "#787878", 5),
             sim = series("sim", "#1e5ac8", 9), wall = series("wall ms per frame, layered", "#148c3c", 13);
  wall.dashed = true;
  auto add = [](PlotSeries* s, const ScaleRun& r, double ms) {
    s->x.push_back(r.summary["model"]["triangles"].get<double>());
    s->y.push_back(ms);
    s->extra[0].values.push_back(r.subdivisions);
  };
  for (const ScaleRun& r : runs) {
    add(r.full_redraw ? &fr : &lr, r, r.summary["render"]["ms"]["p50"].get<double>());
    if (!r.full_redraw) {
      add(&sim, r, r.summary["sim"]["ms"]["p50"].get<double>());
      add(&wall, r, 1000.0 * r.summary["wall_s_per_scene_s"].get<double>() / frame_hz);
    }
  }
  spec.series = {lr, fr, sim, wall};
  return spec;
}

}  // namespace

Result<std::string> run_bench_scale(const std::string& scene_path, const BenchScaleOptions& opt, PlotSpec* plot_spec) {
  auto scene = load_scene(scene_path);
  if (!scene) return scene.error();
  // outputs checked before minutes of measuring
  if (!opt.json_path.empty())
    if (auto st = check_output_target(opt.json_path, "bench json"); !st) return st.error();
  if (!opt.plot_path.empty())
    if (auto st = check_plot_targets(opt.plot_path); !st) return st.error();
  if (opt.max_subdivisions < 0 || opt.max_subdivisions > 7)
    return make_error("bench scale: --max-subdivisions ", std::to_string(opt.max_subdivisions), " is outside [0, 7]");
  // a scene that already subdivides starts there
  const int first = std::max(scene.value().mesh.subdivisions, 0);  // "auto" (kAutoSubdivisions) from none
  const int last = std::max(first, opt.max_subdivisions);
  // the runs' frames go to a work folder removed at the end: only the figures are kept
  const char* tmp_env = std::getenv("TMPDIR");
  std::string tmpl = std::string(tmp_env != nullptr && tmp_env[0] != '\0' ? tmp_env : "/tmp") + "/palpate_scale_XXXXXX";
  std::vector<char> buf(tmpl.begin(), tmpl.end());
  buf.push_back('\0');
  if (::mkdtemp(buf.data()) == nullptr) return make_error("bench scale: cannot create a work folder like '", tmpl, "'");
  const std::string work_dir = buf.data();
  std::vector<ScaleRun> runs;
  Status failed = Ok{};
  for (int k = first; k <= last && failed.ok(); ++k) {
    for (bool full : {false, true}) {
      if (full && !opt.full_redraw) continue;
      if (!opt.quiet)
        std::fprintf(stderr, "bench scale: %s subdivided %d time%s, %s ...\n", scene.value().name.c_str(), k,
                     k == 1 ? "" : "s", full ? "full redraw" : "layered");
      auto r = record_in_child(scene.value(), k, full, opt.duration_s, work_dir);
      if (!r) {
        failed = r.error();
        break;
      }
      runs.push_back(std::move(r).value());
    }
  }
  std::error_code ec;
  fs::remove_all(work_dir, ec);
  if (!failed.ok()) return failed.error();

  if (!opt.json_path.empty()) {
    nlohmann::json j;
    j["scene"] = scene_path;
    j["duration_s"] = opt.duration_s > 0.0 ? opt.duration_s : scene.value().duration_s;
    j["rows"] = nlohmann::json::array();
    for (const ScaleRun& r : runs) j["rows"].push_back(row_json(r));
    if (auto st = write_file_atomic(opt.json_path, j.dump(2) + "\n", "bench json"); !st) return st.error();
  }
  if (plot_spec != nullptr && !opt.plot_path.empty()) *plot_spec = plot(runs, scene_path, scene.value().rates.frame_hz);
  return table(runs);
}

}  // namespace palpate
