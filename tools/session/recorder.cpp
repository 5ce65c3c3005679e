#include "tools/session/recorder.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/clock.h"
#include "core/stats.h"
#include "haptics/latency_histogram.h"
#include "haptics/replay_device.h"
#include "haptics/servo.h"
#include "haptics/servo_runner.h"
#include "tools/session/contact_report.h"
#include "tools/session/device_factory.h"
#include "tools/session/budget_report.h"
#include "tools/session/frame_stage.h"
#include "tools/session/live_feed.h"
#include "tools/session/lockstep.h"
#include "tools/session/material_report.h"
#include "tools/session/model.h"
#include "tools/session/relative_keys.h"
#include "tools/session/video_output.h"

namespace palpate {
namespace fs = std::filesystem;
namespace {


// Files a recording writes in its output folder besides frames/frame_*.png (and their temporaries); a new run
// removes an earlier run's, summary first, so an interrupted run never sits beside another run's summary or log.
constexpr const char* kRunFiles[] = {"summary.json", "summary.json.tmp", "haptic.csv", "haptic.csv.partial",
                                     "recording.mp4", "device_events.csv"};

// Creates out/ and out/frames, checks it can be written, clears the files of an earlier recording there.
Status prepare_output(const std::string& out, bool render, std::string* frames_dir) {
  std::error_code ec;
  // a link to nowhere would otherwise be reported as "File exists" by create_directories
  if (fs::is_symlink(fs::symlink_status(out, ec)) && !fs::exists(out, ec))
    return make_error("output '", out, "': is a symbolic link to '", fs::read_symlink(out, ec).string(),
                      "', which does not exist");
  *frames_dir = (fs::path(out) / "frames").string();
  // frames/ only when frames are drawn (--no-render leaves no empty folder)
  fs::create_directories(render ? fs::path(*frames_dir) : fs::path(out), ec);
  if (ec) return make_error("output '", out, "': cannot create folder: ", ec.message());
  // the probe is created, never opened through a link planted under its name
  const std::string probe = (fs::path(out) / ".palpate_write_probe").string();
  ::unlink(probe.c_str());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) return make_error("output '", out, "': cannot write files there: ", std::strerror(errno));
  ::close(fd);
  ::unlink(probe.c_str());
  // one folder is one run: the earlier run's files go before anything of this one is written (a link under
  // one of these names is removed, never followed)
  for (const char* name : kRunFiles) {
    const std::string path = (fs::path(out) / name).string();
    if (::unlink(path.c_str()) != 0 && errno != ENOENT)
      return make_error("output '", out, "': cannot remove the previous run's ", name, ": ", std::strerror(errno));
  }
  for (const auto& e : fs::directory_iterator(*frames_dir, ec))
    if (e.path().extension() == ".png" && e.path().filename().string().rfind("frame_", 0) == 0)
      if (::unlink(e.path().c_str()) != 0 && errno != ENOENT)
        return make_error("output '", out, "': cannot remove the previous run's ", e.path().string(), ": ",
                          std::strerror(errno));
  if (!render) fs::remove(*frames_dir, ec);  // an earlier run's folder, now empty (kept if anything else is in it)
  return Ok{};
}

nlohmann::json ms_json(const std::vector<double>& v) {
  return {{"p50", percentile(v, 0.5)}, {"p99", percentile(v, 0.99)}, {"max", percentile(v, 1.0)}, {"count", v.size()}};
}

nlohmann::json hist_json(const LatencyHistogram& h) {
  const std::string over = "over_" + std::to_string(static_cast<int64_t>(h.range_us() / 1000.0)) + "ms";
  return {{"p50", h.quantile_us(0.5)}, {"p99", h.quantile_us(0.99)}, {"p999", h.quantile_us(0.999)},
          {"max", h.max_us()}, {"count", h.count()}, {over, h.overflow()}};
}

// A single progress line on stderr: rewritten in place on a terminal, one line a second otherwise.
class Progress {
 public:
  Progress(bool quiet, std::string name, double duration_s)
      : quiet_(quiet), tty_(isatty(STDERR_FILENO)), name_(std::move(name)), duration_s_(duration_s),
        start_(std::chrono::steady_clock::now()) {}
  void update(double t_s, int64_t frame, int64_t frames, bool force = false) {
    if (quiet_) return;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (!force && wall - last_ < (tty_ ? 0.1 : 1.0)) return;
    last_ = wall;
    std::fprintf(stderr, "%srecord %s: %6.2f / %.2f s scene, frame %lld / %lld, %.1f s wall%s", tty_ ? "\r" : "",
                 name_.c_str(), t_s, duration_s_, static_cast<long long>(frame), static_cast<long long>(frames), wall,
                 tty_ ? "   " : "\n");
    std::fflush(stderr);
  }
  void done() {
    if (!quiet_ && tty_) std::fputc('\n', stderr);
  }

 private:
  bool quiet_, tty_;
  std::string name_;
  double duration_s_;
  std::chrono::steady_clock::time_point start_;
  double last_ = -1.0;
};

}  // namespace

Result<RecordResult> record_scene(const Scene& scene_in, const RecordOptions& opt) {
  Scene scene = scene_in;
  if (opt.duration_s > 0.0) scene.duration_s = opt.duration_s;
  const RunMode mode = opt.override_mode ? opt.mode : scene.run_mode;
  const bool lockstep = mode == RunMode::kLockstep;

  // inputs first: a bad mesh leaves no output folder behind
  const auto load0 = std::chrono::steady_clock::now();
  auto model_r = load_model(scene);
  if (!model_r) return model_r.error();
  const double startup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - load0).count();
  const Model& model = model_r.value();
  if (auto st = resolve_relative_keys(model, &scene); !st) return st.error();
  // the device is opened (and checked) before any output exists: a missing link, plugin or replay log, or an
  // unknown driver leaves no frames/ or haptic.csv.partial behind
  const bool rate_given = opt.servo_rate_hz > 0.0;
  const Rates rates{rate_given ? opt.servo_rate_hz : scene.servo_rate_hz, kDefaultFrameRate_hz};
  auto device_r = make_device(scene, opt.device, rates.servo_hz);
  if (!device_r) return device_r.error();
  // an explicit video path that can never be written fails before any output exists
  if (!opt.video_path.empty() && !opt.video_optional)
    if (auto st = check_output_target(opt.video_path, "video"); !st) return st.error();
  std::string frames_dir;
  if (auto st = prepare_output(opt.out_dir, opt.render, &frames_dir); !st) return st.error();

  // rendering: the context lives on this (the sim) thread
  std::unique_ptr<GlContext> gl;
  std::unique_ptr<Renderer> renderer;
  std::unique_ptr<PngWriter> writer;
  PngWriterConfig png;
  png.threads = opt.png_threads > 0 ? opt.png_threads : lockstep ? kLockstepPngThreads : 1;
  png.codec = opt.png_codec;
  png.keep_alpha = opt.png_keep_alpha;
  if (opt.render) {
    auto ctx = create_gl_context(scene.render.width, scene.render.height, scene.render.backend);
    if (!ctx) return ctx.error();
    gl = std::move(ctx).value();
    const RenderStyle style = scene.render.style;
    const Aabb box = Aabb::of(model.rest.vertices_m);
    renderer = std::make_unique<Renderer>(gl.get(), style,
                                          Camera::framing(box.min_m, box.max_m,
                                                          static_cast<double>(scene.render.width) / scene.render.height));
    renderer->set_layered(!opt.full_redraw);
    // lockstep: two encoder threads use the core the single sim/render thread leaves idle; realtime: one, so
    // the servo's core is not contended by a second encoder
    writer = std::make_unique<PngWriter>(frames_dir, scene.render.width, scene.render.height, 6, png);
  }
  auto video_r = open_recording_video(opt.render ? opt.video_path : "", opt.video_optional, scene.render.width,
                                      scene.render.height, static_cast<int>(std::lround(rates.frame_hz)));
  if (!video_r) return video_r.error();
  RecordingVideo& video = video_r.value();

  HapticLog log;
  const std::string csv_path = (fs::path(opt.out_dir) / "haptic.csv").string();
  if (auto st = log.open(csv_path); !st) return st.error();

  Device& device = *device_r.value();
  const ServoParams sp = servo_params_for(scene, device.specs(), rates.servo_hz);
  const CouplingLimit coupling = coupling_limit(scene, device.specs(), rates.servo_hz);
  SpscQueue<HapticSample> samples(8192);
  auto local_model = std::make_unique<TripleBuffer<LocalModel>>();
  Servo servo(sp, &device, &samples, local_model.get());
  WallClock budget_clock;  // realtime frames keep lattice.budget_ms in wall time (lockstep ones have no deadline)
  FrameStage stage(scene, model, &samples, local_model.get(), renderer.get(), writer.get(), &log);
  stage.set_step_dt(rates.frame_period_s());
  if (!lockstep) stage.use_budget(&budget_clock);
  stage.set_video(video.writer.get());
  stage.set_live(opt.live);

  const int64_t frames = rates.frames(scene.duration_s);
  Progress progress(opt.quiet, scene.name, scene.duration_s);
  const auto wall0 = std::chrono::steady_clock::now();
  ServoTiming timing;
  LatencyHistogram frame_latency(100'000);  // realtime: frame start - frame deadline, 100 us buckets to 200 ms
  int64_t frames_late = 0;
  bool memory_locked = false;

  if (lockstep) {
    // virtual clock: rates.servo_hz ticks and rates.frame_hz frames per scene-second, in a fixed order
    run_lockstep(
        rates, scene.duration_s,
        [&](int64_t f, double t) {
          stage.frame(f, t, true);
          progress.update(t, f + 1, frames);
        },
        [&](int64_t i, double t) {
          const int64_t c0 = monotonic_ns();
          servo.tick(i, t);
          timing.compute.add(monotonic_ns() - c0);
        });
  } else {
    std::string mem_refused;
    const bool locked = opt.lock_memory && lock_process_memory(&mem_refused);
    ServoRunnerConfig cfg;
    cfg.rate_hz = rates.servo_hz;
    cfg.spin_us = opt.spin_us >= 0 ? opt.spin_us : default_spin_us(rates.servo_hz);
    cfg.rt.fifo_priority = opt.fifo_priority;
    cfg.rt.cpu = opt.servo_cpu;
    cfg.max_ticks = rates.ticks(scene.duration_s);  // the servo ends on time by itself
    ServoRunner runner(&servo, cfg);
    const int64_t t0_ns = monotonic_ns() + 5'000'000;
    const RtGrant& grant = runner.start(t0_ns);
    // said once: what the system refused and what the servo runs with instead (the summary says the same)
    std::string refused = grant.refused;
    if (opt.lock_memory && !locked) refused += (refused.empty() ? "" : "; ") + mem_refused;
    if (!refused.empty())
      std::fprintf(stderr, "palpate: servo: refused: %s; running with %s%s\n", refused.c_str(),
                   grant.fifo ? "SCHED_FIFO" : "normal priority", grant.timer_slack_1ns ? ", timer slack 1 ns" : "");
    const double frame_ns = 1e9 * rates.frame_period_s();
    for (int64_t f = 0; f < frames; ++f) {
      const int64_t deadline = t0_ns + static_cast<int64_t>(std::llround(static_cast<double>(f) * frame_ns));
      sleep_until_ns(deadline);
      const int64_t late = monotonic_ns() - deadline;
      frame_latency.add(late);
      if (opt.live) opt.live->set_frame_late_ns(late);
      // a frame a whole period late is skipped (counted), so the loop catches up with the wall clock
      if (late > static_cast<int64_t>(frame_ns)) {
        ++frames_late;
        if (opt.live) opt.live->frame_skipped();
        continue;
      }
      stage.frame(f, static_cast<double>(f) * rates.frame_period_s(), false);
      progress.update(static_cast<double>(f) * rates.frame_period_s(), f + 1, frames);
    }
    runner.join();  // the servo ends by itself after the scene's ticks
    timing = runner.timing();
    timing.rt.refused = refused;
    memory_locked = locked;
  }
  stage.drain_remaining();
  progress.update(scene.duration_s, frames, frames, true);
  progress.done();
  if (writer) writer->finish();
  const Status video_status = finish_recording_video(&video);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const Status log_status = log.close();
  const Status events_status = write_device_events(device, opt.out_dir, opt.quiet);
  // a recording that never touched says how close the tool came (from the log just written)
  std::string no_contact;
  if (servo.counters().max_force_N == 0.0 && log_status)
    if (auto rows = load_haptic_csv(csv_path)) no_contact = no_contact_note(scene, model, rows.value());

  const FrameStats& fst = stage.stats();
  const ServoCounters& sc = servo.counters();
  nlohmann::json j;
  j["scene"] = scene.path;
  j["mode"] = name_of(lockstep ? RunMode::kLockstep : RunMode::kRealtime);
  j["interaction"] = mode_name(scene.mode);
  j["duration_s"] = scene.duration_s;
  j["model"] = {{"vertices", model.rest.vertices_m.size()}, {"triangles", model.rest.triangles.size()},
                {"startup_s", startup_s}};
  // what the material became on the lattice (nu represented, total mass)
  if (scene.lattice.material.enabled) j["material"] = material_summary(scene, model.grid);
  j["frames_written"] = writer ? writer->frames_written() : 0;
  j["frames_dropped"] = fst.frames_dropped;
  j["servo_ticks"] = sc.ticks;
  j["max_force_N"] = sc.max_force_N;
  if (!no_contact.empty()) j["no_contact"] = no_contact;
  j["max_displacement_m"] = fst.max_displacement_m;
  j["nan_events"] = fst.nan_events;
  j["dropped_samples"] = sc.dropped_samples;
  j["rejected_inputs"] = sc.rejected_inputs;
  j["no_readings"] = sc.no_readings;
  // the coupling used and the limit that set it: the scene's ask, a stiffness limit, or the passivity bound
  // 2b/T at this rate (b the device's damping)
  j["coupling"] = {{"stiffness_N_per_m", sp.coupling_N_per_m},
                   {"capped", sp.coupling_N_per_m < scene.device.coupling_N_per_m},
                   {"bound", coupling.bound},
                   {"limits_N_per_m", {{"scene", coupling.scene_N_per_m},
                                       {"scene_max", coupling.scene_max_N_per_m},
                                       {"device_max", coupling.device_max_N_per_m},
                                       {"passivity", coupling.passivity_max_N_per_m}}},
                   {"device_damping_Ns_per_m", coupling.damping_Ns_per_m},
                   {"passivity", sp.passivity},
                   {"passivity_activations", sc.passivity_activations},
                   {"passivity_dissipated_J", sc.passivity_dissipated_J},
                   {"ramps", sc.ramps}};
  j["haptic_rows"] = log.rows();
  j["servo"] = {{"clock", lockstep ? "virtual" : "wall"},
                {"latency_us", hist_json(timing.wake_latency)},
                {"compute_us", hist_json(timing.compute)},
                {"overruns", timing.overruns},
                {"first_overrun_ticks", std::vector<int64_t>(timing.first_overrun_ticks.begin(),
                                                             timing.first_overrun_ticks.begin() + timing.overrun_ticks_recorded)},
                {"rate_hz", rates.servo_hz},
                {"rate_from", rate_given ? "--servo-rate" : "scene"},
                {"spin_us", lockstep ? 0 : (opt.spin_us >= 0 ? opt.spin_us : default_spin_us(rates.servo_hz))},
                {"rt", {{"memory_locked", memory_locked}, {"sched_fifo", timing.rt.fifo}, {"priority", timing.rt.priority},
                        {"cpu", timing.rt.cpu}, {"timer_slack_1ns", timing.rt.timer_slack_1ns}, {"refused", timing.rt.refused}}}};
  j["sim"] = {{"ms", ms_json(fst.sim_ms)},
              {"cpu_ms", ms_json(fst.sim_cpu_ms)},
              {"integrator", integrator_name(scene.lattice.integrator)},
              {"max_substeps", fst.max_substeps},
              {"nodes", fst.lattice_nodes},
              {"springs", fst.lattice_springs},
              {"vertices", fst.lattice_vertices},
              {"per_frame_mean", {{"nodes", static_cast<double>(fst.node_frames) / std::max<int64_t>(1, fst.frames)},
                                  {"springs", static_cast<double>(fst.spring_frames) / std::max<int64_t>(1, fst.frames)},
                                  {"vertices", static_cast<double>(fst.vertex_frames) / std::max<int64_t>(1, fst.frames)}}},
              {"step_ms", ms_json(fst.step_ms)},
              {"step_cpu_ms", ms_json(fst.step_cpu_ms)},
              {"frames_stepped", fst.frames_stepped},
              {"frames_resting", fst.frames_resting},
              {"region_moves", fst.region_moves},
              {"divergence_events", fst.divergence_events},
              {"frame_latency_us", hist_json(frame_latency)},
              {"frames_late", frames_late}};
  if (scene.lattice.budget_ms > 0.0) j["budget"] = budget_summary(scene, stage, lockstep);
  if (scene.mode == InteractionMode::kCut) {
    const CutModel* cut = stage.cut_model();
    j["cut"] = {{"frames_cutting", fst.frames_cutting},
                {"springs_cut", fst.springs_cut},
                {"springs_left", stage.lattice() ? stage.lattice()->springs.size() : 0},
                {"triangles", cut ? cut->triangles().size() : 0},
                {"triangles_added", fst.triangles_added},
                {"vertices_added", fst.vertices_added},
                {"free_nodes", fst.free_nodes},
                {"sim_ms_cutting", ms_json(fst.cutting_ms)},
                {"sim_ms_after_cut", ms_json(fst.after_cut_ms)}};
  }
  j["render"] = {{"ms", ms_json(fst.render_ms)}, {"backend", gl ? gl->backend_name() : "none"},
                 {"width", scene.render.width}, {"height", scene.render.height},
                 {"frames_layered", fst.frames_layered}, {"layer_builds", renderer ? renderer->layer_builds() : 0}};
  j["png"] = {{"ms", ms_json(writer ? writer->png_ms() : std::vector<double>{})},
              {"write_errors", writer ? writer->write_errors() : 0},
              {"threads", png.threads},
              {"codec", png.codec == PngCodec::kZlib ? "zlib" : "libdeflate"},
              {"keep_alpha", png.keep_alpha}};
  // realtime: which scene frame each file shows (files are numbered without gaps; lockstep: file i is frame i)
  if (!lockstep) j["frames_scene_index"] = fst.written_frames;
  j["video"] = video_json(video, opt.render ? "off: no video path (--no-video)" : "no frames (--no-render)");
  j["wall_s"] = wall_s;
  j["wall_s_per_scene_s"] = wall_s / scene.duration_s;
  if (lockstep) j["state_hash"] = stage.state_hash();
  j["device"] = device.report();
  j["outputs"] = {{"frames", opt.render ? nlohmann::json(frames_dir) : nlohmann::json(nullptr)}, {"haptic_csv", csv_path}};

  RecordResult res;
  res.summary_path = (fs::path(opt.out_dir) / "summary.json").string();
  res.summary_json = j.dump(2) + "\n";
  res.frames_written = writer ? writer->frames_written() : 0;
  if (video.writer && video.error.empty()) res.video_path = video.path;
  res.state_hash = lockstep ? stage.state_hash() : "";
  res.servo_timing = timing;
  res.frame_latency = frame_latency;
  res.frames_late = frames_late;
  res.frames_dropped = fst.frames_dropped;
  res.nan_events = fst.nan_events;
  res.divergence_events = fst.divergence_events;
  res.no_contact = no_contact;
  const Status summary_status = write_file_atomic(res.summary_path, res.summary_json, "summary");
  if (opt.live) {
    // the live view ends on the figures summary.json holds
    LiveFigures f;
    f.frames = fst.frames;
    f.frames_written = res.frames_written;
    f.frames_dropped = fst.frames_dropped;
    f.frames_late = frames_late;
    f.servo_ticks = sc.ticks;
    f.overruns = timing.overruns;
    f.servo_p50_us = timing.wake_latency.quantile_us(0.5);
    f.servo_p99_us = timing.wake_latency.quantile_us(0.99);
    f.t_s = scene.duration_s;
    f.max_force_N = sc.max_force_N;
    opt.live->finish(f);
  }
  if (!summary_status && log_status && !(writer && writer->write_errors() > 0)) return summary_status.error();  // a full disk: the first file that failed
  if (writer && writer->write_errors() > 0)
    return make_error(std::to_string(writer->write_errors()), " frame(s) could not be written: ", writer->first_error());
  if (!video_status) return video_status.error();
  if (!log_status) return log_status.error();
  if (!events_status) return events_status.error();
  return res;
}

}  // namespace palpate
