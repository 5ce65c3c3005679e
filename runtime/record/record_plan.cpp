#include "runtime/record/record_plan.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <filesystem>

#include "core/atomic_file.h"
#include "sim/solvers/stability.h"
#include "runtime/session/device_factory.h"
#include "runtime/record/material_report.h"

namespace palpate {
namespace fs = std::filesystem;
namespace {

// Files of a recording's output folder that a video must never replace.
constexpr const char* kOwnFiles[] = {"summary.json", "summary.json.tmp", "haptic.csv", "haptic.csv.partial",
                                     "device_events.csv", "device_events.csv.partial"};

// path made absolute and normal, lexically (no file is read)
fs::path normal(const std::string& path) { return fs::absolute(fs::path(path)).lexically_normal(); }

// The video path refused when it is one of the recording's own outputs.
Status check_video_against_outputs(const RecordPlan& p) {
  const fs::path video = normal(p.video_path);
  const fs::path out = normal(p.out_dir);
  const fs::path frames = normal(p.frames_dir);
  const std::string what = "--video '" + p.video_path + "'";
  if (video == out || video == frames) return make_error(what, ": is the output folder, not a file");
  for (const char* name : kOwnFiles)
    if (video == out / name)
      return make_error(what, ": is the recording's own ", name, " in '", p.out_dir, "'; choose another name");
  if (video.parent_path() == frames && video.filename().string().rfind("frame_", 0) == 0)
    return make_error(what, ": is where the recording writes its frames ('", p.frames_dir,
                      "/frame_*.png'); choose another name");
  return Ok{};
}

// The nearest folder of `path` that exists (path itself when it does), or empty.
fs::path existing_ancestor(fs::path p) {
  std::error_code ec;
  while (!p.empty() && !fs::exists(p, ec)) {
    if (p == p.parent_path()) return {};
    p = p.parent_path();
  }
  return p;
}

}  // namespace

Result<RecordPlan> plan_record(const Scene& scene_in, const RecordOptions& opt) {
  RecordPlan p;
  p.scene = scene_in;
  Scene& scene = p.scene;
  // the command line's overrides, applied here once: everything after reads the plan's scene
  if (opt.duration_s > 0.0) scene.duration_s = opt.duration_s;
  p.rate_given = opt.servo_rate_hz > 0.0;
  if (p.rate_given) scene.rates.servo_hz = opt.servo_rate_hz;
  const auto driver = device_driver(scene, opt.device);
  if (!driver) return driver.error();
  p.driver = driver.value();
  // the mode: asked for, else a device in another process runs on its own wall clock and so does the recording
  p.mode_from = "scene";
  if (p.driver == DeviceDriver::kBrowser && opt.override_mode && opt.mode == RunMode::kLockstep)
    return make_error("--device browser: a person's pointer runs on the wall clock; --mode lockstep cannot drive it "
                      "(record with --mode realtime, then replay its haptic.csv in lockstep with --device replay:DIR)");
  if (opt.override_mode) {
    scene.run_mode = opt.mode;
    p.mode_from = "--mode";
  } else if (p.driver == DeviceDriver::kBrowser) {
    scene.run_mode = RunMode::kRealtime;
    p.mode_from = "browser device";
  } else if (p.driver == DeviceDriver::kShm) {
    scene.run_mode = RunMode::kRealtime;
    p.mode_from = "shm device";
  }
  p.lockstep = scene.run_mode == RunMode::kLockstep;
  p.render = opt.render;

  p.out_dir = opt.out_dir.empty() ? (fs::path("out") / scene.name).string() : opt.out_dir;
  p.frames_dir = (fs::path(p.out_dir) / "frames").string();
  p.summary_path = (fs::path(p.out_dir) / "summary.json").string();
  p.haptic_csv_path = (fs::path(p.out_dir) / "haptic.csv").string();

  // the video: an explicit path must be made; the default one (<out>/recording.mp4) is made when it can be
  const bool wanted = !opt.video_path.empty() || opt.video_optional;
  if (!opt.render) {
    p.video_reason = "--no-render: no frames";
    if (!opt.video_path.empty() && !opt.video_optional)
      p.warnings.push_back("--video needs frames; --no-render records none");
  } else if (!wanted) {
    p.video_reason = "--no-video";
  } else {
    p.video_path = opt.video_path.empty() ? (fs::path(p.out_dir) / "recording.mp4").string() : opt.video_path;
    p.video_optional = opt.video_optional;
    p.video = !p.lockstep && opt.video_optional ? VideoPolicy::kAfterRun : VideoPolicy::kDuring;
    if (auto st = check_video_against_outputs(p); !st) return st.error();
  }

  // said once before starting: the integrator's stability at the frame step, the material, flags that do not apply
  if (const std::string w = integrator_warning(scene.lattice, scene.rates.frame_period_s()); !w.empty())
    p.warnings.push_back(w);
  for (std::string& w : material_warnings(scene)) p.warnings.push_back(std::move(w));
  if (opt.realtime_flags && p.lockstep)
    p.warnings.push_back("--spin-us and --priority apply to realtime recordings; this one is lockstep");
  return p;
}

Status check_plan_outputs(const RecordPlan& p) {
  std::error_code ec;
  // the output folder: a folder, or a path whose nearest existing folder can be written (it is created there)
  const fs::path out(p.out_dir);
  if (fs::exists(out, ec) && !fs::is_directory(out, ec))
    return make_error("output '", p.out_dir, "': is not a folder");
  if (fs::is_symlink(fs::symlink_status(out, ec)) && !fs::exists(out, ec))
    return make_error("output '", p.out_dir, "': is a symbolic link to '", fs::read_symlink(out, ec).string(),
                      "', which does not exist");
  const fs::path base = existing_ancestor(fs::absolute(out, ec));
  if (base.empty() || !fs::is_directory(base, ec))
    return make_error("output '", p.out_dir, "': cannot create folder: '", base.string(), "' is not a folder");
  if (::access(base.c_str(), W_OK) != 0)
    return make_error("output '", p.out_dir, "': cannot write in '", base.string(), "'");
  if (p.video == VideoPolicy::kNone) return Ok{};
  // the video: not a link nor a non-regular file; its folder exists (or is the output folder) and can be written
  if (auto st = check_output_target(p.video_path, "video", true); !st) return st.error();
  // (the output folder and its frames/ are created by the run)
  const fs::path folder = fs::absolute(fs::path(p.video_path), ec).parent_path().lexically_normal();
  if (folder == normal(p.out_dir) || (p.render && folder == normal(p.frames_dir))) return Ok{};
  if (!fs::is_directory(folder, ec))
    return make_error("video '", p.video_path, "': folder '", folder.string(), "' does not exist");
  // a probe file, created and removed (access() says yes to root on folders that take no files, e.g. /proc)
  const std::string probe = (folder / ".palpate_video_probe").string();
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0)
    return make_error("video '", p.video_path, "': cannot write in folder '", folder.string(), "': ", std::strerror(errno));
  ::close(fd);
  ::unlink(probe.c_str());
  return Ok{};
}

}  // namespace palpate
