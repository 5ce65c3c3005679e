#include "runtime/record/recorder.h"

#include "runtime/record/color_pass.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <new>
#include <filesystem>
#include <memory>

#include <optional>
#include <system_error>

#include "core/atomic_file.h"
#include "core/clock.h"
#include "core/printable.h"
#include "haptics/servo/latency_histogram.h"
#include "haptics/devices/browser_device.h"
#include "haptics/devices/replay_device.h"
#include "haptics/servo/servo_runner.h"
#include "render/gl_context_factory.h"
#include "sim/solvers/frame_budget.h"
#include "runtime/session/contact_report.h"
#include "runtime/session/device_factory.h"
#include "runtime/live/live_feed.h"
#include "runtime/session/model.h"
#include "runtime/record/material_report.h"
#include "runtime/record/memory_reserve.h"
#include "runtime/record/record_plan.h"
#include "runtime/session/relative_keys.h"
#include "runtime/session/session.h"
#include "runtime/record/progress.h"
#include "runtime/record/summary.h"
#include "runtime/record/video_output.h"

namespace palpate {
namespace fs = std::filesystem;

namespace {

// Files a recording writes in its output folder besides frames/frame_*.png (and their temporaries); a new run
// removes an earlier run's, summary first, so an interrupted run never sits beside another run's summary or log.
constexpr const char* kRunFiles[] = {"summary.json", "summary.json.tmp", "haptic.csv", "haptic.csv.partial",
                                     "recording.mp4", "device_events.csv"};

// An earlier recording in out/ (any of its files, or frames) is moved aside into out/previous-N/ (the first N free),
// frames under its frames/: a re-run never deletes a run's data. Returns the folder it went to, or "" when there was
// none. Renames only (the same file system): nothing is copied, and a failure names the file.
Result<std::string> move_earlier_run_aside(const std::string& out, const std::string& frames_dir) {
  std::error_code ec;
  std::vector<fs::path> files, frames;
  for (const char* name : kRunFiles)
    if (fs::exists(fs::symlink_status(fs::path(out) / name, ec))) files.push_back(fs::path(out) / name);
  for (const auto& e : fs::directory_iterator(frames_dir, ec))
    if (e.path().extension() == ".png" && e.path().filename().string().rfind("frame_", 0) == 0) frames.push_back(e.path());
  if (files.empty() && frames.empty()) return std::string();
  fs::path aside;
  for (int n = 1;; ++n) {
    aside = fs::path(out) / ("previous-" + std::to_string(n));
    if (!fs::exists(fs::symlink_status(aside, ec))) break;
  }
  fs::create_directories(frames.empty() ? aside : aside / "frames", ec);
  if (ec) return make_error("output '", out, "': cannot make '", aside.string(), "' for the earlier run: ", ec.message());
  // the summary first, as a run's files are cleared: an interrupted move never leaves a summary beside other frames
  for (const fs::path& f : files)
    if (::rename(f.c_str(), (aside / f.filename()).c_str()) != 0)
      return make_error("output '", out, "': cannot move the earlier run's ", f.string(), " aside: ", std::strerror(errno));
  for (const fs::path& f : frames)
    if (::rename(f.c_str(), (aside / "frames" / f.filename()).c_str()) != 0)
      return make_error("output '", out, "': cannot move the earlier run's ", f.string(), " aside: ", std::strerror(errno));
  return aside.string();
}

// Creates out/ and out/frames, checks it can be written, moves an earlier recording there aside (*moved_to: where).
Status prepare_output(const std::string& out, bool render, std::string* frames_dir, std::string* moved_to) {
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
  // one folder is one run: the earlier run's files go aside before anything of this one is written (a link under
  // one of these names is moved as a link, never followed); what is left (temporaries) is removed
  auto aside = move_earlier_run_aside(out, *frames_dir);
  if (!aside) return aside.error();
  *moved_to = aside.value();
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

// Everything a recording opens before it runs, inputs first: a bad mesh or device leaves no output folder behind.
// Not movable (the log, the scene the device reads its rates from); filled in place by open_recording.
struct Recording {
  const RecordPlan* plan = nullptr;
  Scene scene;                     // the plan's, the keyframes resolved against the model
  double startup_s = 0.0;          // loading the model
  std::optional<Model> model;
  std::unique_ptr<Device> device;
  std::string frames_dir, csv_path;
  std::unique_ptr<GlContext> gl;   // the context lives on this (the sim) thread
  std::unique_ptr<Renderer> renderer;
  std::unique_ptr<PngWriter> writer;
  PngWriterConfig png;
  RecordingVideo video;
  HapticLog log;
};

Status open_recording(const RecordPlan& plan, const RecordOptions& opt, Recording* rec) {
  rec->plan = &plan;
  rec->scene = plan.scene;
  Scene& scene = rec->scene;

  // inputs first: a bad mesh leaves no output folder behind
  const auto load0 = std::chrono::steady_clock::now();
  auto model_r = load_model(scene);
  if (!model_r) return model_r.error();
  rec->startup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - load0).count();
  rec->model.emplace(std::move(model_r).value());
  if (plan.driver == DeviceDriver::kBrowser) {
    // the page's controls may switch to touch (whose checks ask whether the surface is closed) and stiffen the
    // material up to the scene's range: the stiffest is checked stable here, before any output exists
    Model& m = *rec->model;
    if (!m.closed) m.closed = closed_surface(m.rest, m.adjacency);
    if (auto st = check_control_range(scene, m); !st) return st.error();
  }
  const Model& model = *rec->model;
  if (auto st = resolve_relative_keys(model, &scene); !st) return st.error();
  if (const std::string w = self_weight_notice(scene, model.rest.vertices_m); !w.empty())
    std::fprintf(stderr, "palpate: warning: %s\n", w.c_str());
  if (const std::string w = mesh_resolution_notice(scene, model.rest, model.grid); !w.empty())
    std::fprintf(stderr, "palpate: warning: %s\n", w.c_str());
  if (model.auto_subdivisions > 0 && !opt.quiet)
    std::fprintf(stderr, "palpate: mesh '%s': subdivided %d time(s) on load (mesh.subdivisions \"auto\"): its triangles "
                 "(median longest edge %.3g mm) were coarser than the lattice's finest cells (%.3g mm), which a surface "
                 "must be finer than to dent under the tool; %zu triangles now (mesh.subdivisions 0 keeps the file's)\n",
                 printable_text(scene.mesh.file).c_str(), model.auto_subdivisions, 1e3 * model.coarse_edge_m,
                 1e3 * model.grid.cell_size_m(std::max(scene.lattice.level, scene.lattice.refine.level)),
                 model.rest.triangles.size());
  // the colours' range, fixed before the first frame: from a first pass of the scripted run
  if (needs_color_pass(scene, opt.render, plan.driver)) {
    if (!opt.quiet) std::fprintf(stderr, "record %s: a first pass without frames, for the colours' range\n", scene.name.c_str());
    const double range = color_pass_range(scene, model, opt.stop);
    (colors_by_strain(scene) ? scene.render.strain_range : scene.render.color_range_m) = range;
  }
  // the device is opened (and checked) before any output exists: a missing link, plugin or replay log, or an
  // unknown driver leaves no frames/ or haptic.csv.partial behind
  auto device_r = make_device(scene, opt.device, opt.browser);
  if (!device_r) return device_r.error();
  rec->device = std::move(device_r).value();
  // the page's pointer moves the tool on the plane the view looks at
  if (auto* b = dynamic_cast<BrowserDevice*>(rec->device.get())) {
    const Aabb box = Aabb::of(model.rest.vertices_m);
    b->set_view(browser_view(scene_camera(scene, box),
                             static_cast<double>(scene.render.width) / scene.render.height,
                             (box.max_m - box.min_m).norm()));
    // before a page steers, the tool waits at the scene's first key (where a scripted run starts)
    if (!scene.trajectory.empty() && !needs_model(scene.trajectory.front()))
      b->set_start(scene.trajectory.front().pos_m);
  }
  // a video path inside frames/ is never written (the frames folder is the recording's own)
  if (auto st = check_video_beside_frames(plan.video_path, plan.frames_dir); !st) return st.error();
  std::string moved_to;
  if (auto st = prepare_output(plan.out_dir, opt.render, &rec->frames_dir, &moved_to); !st) return st.error();
  if (!moved_to.empty())
    std::fprintf(stderr, "palpate: '%s' held an earlier recording: moved to '%s' (a run never deletes another's data)\n",
                 plan.out_dir.c_str(), moved_to.c_str());

  rec->png.threads = opt.png_threads > 0 ? opt.png_threads : plan.lockstep ? kLockstepPngThreads : 1;
  rec->png.codec = opt.png_codec;
  rec->png.keep_alpha = opt.png_keep_alpha;
  if (opt.render) {
    auto ctx = create_gl_context(scene.render.width, scene.render.height, scene.render.backend);
    if (!ctx) return ctx.error();
    rec->gl = std::move(ctx).value();
    const RenderStyle style = scene.render.style;
    const Aabb box = Aabb::of(model.rest.vertices_m);
    rec->renderer = std::make_unique<Renderer>(
        rec->gl.get(), style,
        scene_camera(scene, box, plan.driver));
    rec->renderer->set_layered(!opt.full_redraw);
    rec->renderer->set_wire_min_edge_px(scene.render.wire_min_edge_px);
    rec->renderer->set_samples(std::max(scene.render.antialias, 0));
    rec->renderer->set_smooth_edges(scene.render.antialias == kAntialiasEdges);
    // lockstep: two encoder threads use the core the single sim/render thread leaves idle; realtime: one, so
    // the servo's core is not contended by a second encoder
    rec->writer = std::make_unique<PngWriter>(rec->frames_dir, scene.render.width, scene.render.height, 6, rec->png);
  }
  auto video_r = open_recording_video(plan.video == VideoPolicy::kDuring ? plan.video_path : "", plan.video_optional,
                                      scene.render.width, scene.render.height, scene.rates.video_fps());
  if (!video_r) return video_r.error();
  rec->video = std::move(video_r).value();

  rec->csv_path = plan.haptic_csv_path;
  rec->log.keep_samples(opt.samples);
  return rec->log.open(rec->csv_path);
}

// What a run that ran out of memory on the sim thread says (summary.json "aborted", and the error line): where it
// stopped. Frames, haptic.csv and summary.json up to there are kept.
std::string out_of_memory_note(const Session& session, int64_t f) {
  char t[32];
  std::snprintf(t, sizeof t, "%.3f", session.frame_time_s(f));
  return "out of memory in frame " + std::to_string(f) + " (scene time " + t + " s); the run stopped there";
}

// What a run ended by a stop request says (summary.json "interrupted"): after which frame it stopped.
std::string interrupted_note(const Session& session, int64_t frames_done) {
  char t[32];
  std::snprintf(t, sizeof t, "%.3f", session.frame_time_s(frames_done));
  return "stopped on request (SIGINT, SIGTERM or SIGHUP) after " + std::to_string(frames_done) + " frame(s), at scene time " + t + " s";
}

bool stop_requested(const RecordOptions& opt) { return opt.stop != nullptr && opt.stop->load(std::memory_order_relaxed); }

// Thrown out of the lockstep frame callback to end the run at a stop request.
struct StopRequested {};

// The lockstep driver: a virtual clock, rates.servo_hz ticks and rates.frame_hz frames per scene-second in a fixed
// order, every frame written; reproducible bit for bit.
RunFigures drive_lockstep(Session& session, double duration_s, const RecordOptions& opt, Progress& progress) {
  const int64_t frames = session.rates().frames(duration_s);
  RunFigures run;
  int64_t done = 0;  // frames finished: the one under way when memory ran out is the next
  try {
    session.run_lockstep(duration_s, [&](int64_t f, double t) {
      done = f + 1;
      progress.update(t, f + 1, frames);
      if (stop_requested(opt)) throw StopRequested{};
      // an allocation failed and was served from the reserve: the run stops as if it had thrown
      if (MemoryReserve::tripped()) throw std::bad_alloc();
    });
  } catch (const std::bad_alloc&) {
    run.aborted = out_of_memory_note(session, done);
    session.finish();
  } catch (const StopRequested&) {
    run.interrupted = interrupted_note(session, done);
    session.finish();
  }
  run.timing.compute = session.lockstep_compute();
  return run;
}

// The realtime driver: the servo on its own thread (ServoRunner, real-time settings as far as granted), the frames
// on this thread at their wall-clock deadlines; a frame a whole period late is skipped.
RunFigures drive_realtime(Session& session, double duration_s, const RecordOptions& opt, Progress& progress) {
  const Rates& rates = session.rates();
  WallClock budget_clock;  // realtime frames keep lattice.budget_ms in wall time (lockstep ones have no deadline)
  session.use_budget(&budget_clock);
  session.keep_deadlines();  // a frame's step ends a frame period after it starts, whatever the solver
  RunFigures run;
  std::string mem_refused;
  const bool locked = opt.lock_memory && lock_process_memory(&mem_refused);
  ServoRunnerConfig cfg;
  cfg.spin_us = opt.spin_us >= 0 ? opt.spin_us : ServoRunnerConfig::kAdaptiveSpin;
  cfg.rt.fifo_priority = opt.fifo_priority;
  cfg.rt.cpu = opt.servo_cpu;
  cfg.max_ticks = rates.ticks(duration_s);  // the servo ends on time by itself
  ServoRunner runner(&session.servo(), rates, cfg);
  // the renderer's one-time set-up before the clock starts, not in frame 0's period (it made frame 1 late)
  session.warm_up();
  const int64_t t0_ns = monotonic_ns() + 5'000'000;
  const RtGrant& grant = runner.start(t0_ns);
  // said once: what the system refused and what the servo runs with instead (the summary says the same)
  std::string refused = grant.refused;
  if (opt.lock_memory && !locked) refused += (refused.empty() ? "" : "; ") + mem_refused;
  if (!refused.empty())
    std::fprintf(stderr, "palpate: servo: refused: %s; running with %s%s\n", refused.c_str(),
                 grant.fifo ? "SCHED_FIFO" : "normal priority", grant.timer_slack_1ns ? ", timer slack 1 ns" : "");
  const int64_t frames = rates.frames(duration_s);
  const double frame_ns = 1e9 * rates.frame_period_s();
  for (int64_t f = 0; f < frames; ++f) {
    if (stop_requested(opt)) {
      run.interrupted = interrupted_note(session, f);
      runner.stop();  // the device's force ramps down with the servo's end, as at the end of any run
      break;
    }
    const int64_t deadline = t0_ns + static_cast<int64_t>(std::llround(static_cast<double>(f) * frame_ns));
    sleep_until_ns(deadline);
    const int64_t late = monotonic_ns() - deadline;
    run.frame_latency.add(late);
    if (opt.live) opt.live->set_frame_late_ns(late);
    // a frame a whole period late is skipped (counted), so the loop catches up with the wall clock
    if (late > static_cast<int64_t>(frame_ns)) {
      ++run.frames_late;
      run.skipped_frames.push_back(f);
      if (opt.live) opt.live->frame_skipped();
      continue;
    }
    try {
      session.frame(f, false);
      progress.update(session.frame_time_s(f), f + 1, frames);
      if (MemoryReserve::tripped()) throw std::bad_alloc();  // served from the reserve: stop here
    } catch (const std::bad_alloc&) {
      run.aborted = out_of_memory_note(session, f);
      runner.stop();  // the device's force ramps down with the servo's end, as at the end of any run
      break;
    }
  }
  runner.join();  // the servo ends by itself after the scene's ticks
  session.finish();
  run.timing = runner.timing();
  run.timing.rt.refused = refused;
  run.memory_locked = locked;
  return run;
}

// After either driver: finishes the outputs, writes summary.json (whatever else failed) and reports the first
// failure, if any.
Result<RecordResult> finish_recording(Recording& rec, const Session& session, const RunFigures& run,
                                      std::chrono::steady_clock::time_point wall0, Progress& progress,
                                      const RecordOptions& opt) {
  const Scene& scene = rec.scene;
  const RecordPlan& plan = *rec.plan;
  const int64_t frames = session.rates().frames(scene.duration_s);
  progress.done(run.interrupted.empty() && run.aborted.empty(), frames);
  if (rec.writer) rec.writer->finish();
  Status video_status = finish_recording_video(&rec.video);
  // a realtime run's default video, from the frames just written (its encoder never ran beside the servo)
  // (a run the request already ended gets its whole video; a request that comes while the video is made ends it)
  if (plan.video == VideoPolicy::kAfterRun && rec.writer && rec.writer->write_errors() == 0)
    make_video_after_run(plan.video_path, rec.frames_dir, rec.writer->frames_written(),
                         session.stage().stats().written_frames, scene.rates.video_fps(), &rec.video,
                         stop_requested(opt) ? nullptr : opt.stop);
  // a stop requested after the run's last frame (while the frames or the video were finished) is a stop all the
  // same: said in summary.json and by the exit status, with everything the run made kept
  RunFigures ran = run;
  if (ran.interrupted.empty() && ran.aborted.empty() && stop_requested(opt))
    ran.interrupted = "stopped on request after the run's last frame, while its outputs were finished" +
                      std::string(rec.video.error.empty() ? "" : " (" + rec.video.error + ")");
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const Status log_status = rec.log.close();
  const Status events_status = write_device_events(*rec.device, plan.out_dir, opt.quiet);
  const ServoCounters& sc = session.servo().counters();
  // a recording that never touched says how close the tool came (from the log just written)
  std::string no_contact;
  if (sc.max_force_N == 0.0 && log_status)
    if (auto rows = load_haptic_csv(rec.csv_path)) no_contact = no_contact_note(scene, *rec.model, rows.value());

  SummaryInputs in;
  in.scene = &scene;
  in.model = &*rec.model;
  in.session = &session;
  in.device = rec.device.get();
  in.run = &ran;
  in.lockstep = plan.lockstep;
  in.rate_given = plan.rate_given;
  in.startup_s = rec.startup_s;
  in.wall_s = wall_s;
  in.gl = rec.gl.get();
  in.renderer = rec.renderer.get();
  in.writer = rec.writer.get();
  in.png = rec.png;
  in.video = &rec.video;
  in.render = opt.render;
  // what the disk holds: after a failed write, the rows of haptic.csv.partial (or none), not the rows buffered
  in.haptic_rows = rec.log.kept_rows();
  in.haptic_csv = rec.log.kept_path();
  if (!log_status) in.haptic_error = log_status.error().message;
  in.no_contact = no_contact;
  in.frames_dir = rec.frames_dir;

  const FrameStats& fst = session.stage().stats();
  RecordResult res;
  res.summary_path = plan.summary_path;
  res.summary_json = recording_summary(in).dump(2) + "\n";
  res.frames_written = rec.writer ? rec.writer->frames_written() : 0;
  if ((rec.video.writer || !rec.video.made_after_run.is_null()) && rec.video.error.empty())
    res.video_path = rec.video.path;
  res.state_hash = plan.lockstep ? session.stage().state_hash() : "";
  res.servo_timing = run.timing;
  res.frame_latency = run.frame_latency;
  res.frames_late = run.frames_late;
  res.frames_dropped = fst.frames_dropped;
  res.nan_events = fst.nan_events;
  res.divergence_events = fst.divergence_events;
  res.no_contact = no_contact;
  res.tool_inside = tool_inside_note(fst);
  res.mesh_notice = rec.model->orientation.notice();
  const Status summary_status = write_file_atomic(res.summary_path, res.summary_json, "summary");
  if (opt.live) {
    // the live view ends on the figures summary.json holds
    LiveFigures f;
    f.frames = fst.frames;
    f.frames_written = res.frames_written;
    f.frames_dropped = fst.frames_dropped;
    f.frames_late = run.frames_late;
    f.servo_ticks = sc.ticks;
    f.overruns = run.timing.overruns;
    f.servo_p50_us = run.timing.wake_latency.quantile_us(0.5);
    f.servo_p99_us = run.timing.wake_latency.quantile_us(0.99);
    f.t_s = scene.duration_s;
    f.max_force_N = sc.max_force_N;
    opt.live->finish(f);
  }
  // a full disk: the first file that failed is named, not summary.json, which fails after it; the line still
  // says when there is no summary
  if (!summary_status && log_status && !(rec.writer && rec.writer->write_errors() > 0)) return summary_status.error();
  const std::string no_summary = summary_status ? "" : " (and no summary: " + summary_status.error().message + ")";
  if (!ran.aborted.empty())
    return make_error(ran.aborted, ": ", std::to_string(res.frames_written), " frame(s), ", std::to_string(in.haptic_rows),
                      " haptic row(s)", summary_status ? " and summary.json kept in '" + plan.out_dir + "'" : no_summary);
  if (!ran.interrupted.empty())
    res.interrupted = ran.interrupted + ": " + std::to_string(res.frames_written) + " frame(s), " +
                      std::to_string(in.haptic_rows) + " haptic row(s) and summary.json kept in '" + plan.out_dir + "'";
  if (rec.writer && rec.writer->write_errors() > 0)
    return make_error(std::to_string(rec.writer->write_errors()), " frame(s) could not be written: ",
                      rec.writer->first_error(), no_summary);
  if (!video_status) return make_error(video_status.error().message, no_summary);
  if (!log_status) return make_error(log_status.error().message, no_summary);
  if (!events_status) return make_error(events_status.error().message, no_summary);
  return res;
}

Result<RecordResult> record_planned_unguarded(const RecordPlan& plan, const RecordOptions& opt) {
  auto rec = std::make_unique<Recording>();
  if (auto st = open_recording(plan, opt, rec.get()); !st) return st.error();
  const SessionOutputs outputs{rec->renderer.get(), rec->writer.get(), &rec->log, rec->video.writer.get(), opt.live};
  Session session(rec->scene, *rec->model, rec->device.get(), outputs);
  Progress progress(opt.quiet, rec->scene.name, rec->scene.duration_s);
  const auto wall0 = std::chrono::steady_clock::now();
  const RunFigures run = plan.lockstep ? drive_lockstep(session, rec->scene.duration_s, opt, progress)
                                       : drive_realtime(session, rec->scene.duration_s, opt, progress);
  return finish_recording(*rec, session, run, wall0, progress, opt);
}

}  // namespace

Result<RecordResult> record_scene(const Scene& scene, const RecordOptions& opt) {
  auto plan = plan_record(scene, opt);
  if (!plan) return plan.error();
  if (auto st = check_plan_outputs(plan.value()); !st) return st.error();
  return record_planned(plan.value(), opt);
}

Result<RecordResult> record_planned(const RecordPlan& plan, const RecordOptions& opt) {
  // out of memory while the run is set up or finished (the frame loop says where it stopped, above) is a line;
  // the reserve lets what was under way when memory ran out finish first
  const MemoryReserve reserve;
  try {
    return record_planned_unguarded(plan, opt);
  } catch (const std::bad_alloc&) {
    return make_error("out of memory while opening or finishing the recording in '", plan.out_dir, "'");
  } catch (const std::system_error& e) {
    // a thread the system would not start (the writer's, the servo's): its limits on threads or memory
    return make_error("the system refused a thread for the recording in '", plan.out_dir, "' (", e.what(),
                      "): its limits on processes or memory (ulimit -u, ulimit -v) leave too little");
  }
}

}  // namespace palpate
