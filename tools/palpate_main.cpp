// palpate: record touch/pull demos headless, inspect meshes.

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>
#include <fstream>
#include <map>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "core/limits.h"

#include "core/atomic_file.h"
#include "core/scene.h"
#include "sim/stability.h"
#include "tools/bench_force.h"
#include "tools/bench_loop.h"
#include "tools/bench_mesh.h"
#include "tools/bench_model.h"
#include "tools/bench_png.h"
#include "tools/bench_scale.h"
#include "tools/bench_sim.h"
#include "tools/cli_checks.h"
#include "tools/info_command.h"
#include "tools/plot.h"
#include "tools/scene_command.h"
#include "tools/session/device_factory.h"
#include "tools/session/live_feed.h"
#include "tools/session/live_server.h"
#include "tools/session/material_report.h"
#include "tools/session/model.h"
#include "tools/session/recorder.h"
#include "tools/video_command.h"

namespace {

volatile std::sig_atomic_t g_interrupted = 0;

// Keeps the live view up after the run for linger_s seconds, or until Ctrl-C / SIGTERM.
void linger(const palpate::LiveServer& server, double linger_s) {
  std::fprintf(stderr, "palpate: live view: the run is over; serving its last frame at %s for %.0f s (Ctrl-C ends)\n",
               server.url().c_str(), linger_s);
  auto on_signal = [](int) { g_interrupted = 1; };
  struct sigaction sa {}, old_int {}, old_term {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(linger_s);
  while (!g_interrupted && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
}

int run_record(const std::string& scene_path, palpate::RecordOptions opt, const std::string& mode, bool realtime_flags,
               bool want_video, const std::string& serve, double serve_linger_s) {
  auto scene = palpate::load_scene(scene_path);
  if (!scene) {
    std::fprintf(stderr, "palpate: %s\n", scene.error().message.c_str());
    return 1;
  }
  if (opt.out_dir.empty()) opt.out_dir = (std::filesystem::path("out") / scene.value().name).string();
  if (want_video && opt.video_path.empty()) opt.video_path = (std::filesystem::path(opt.out_dir) / "recording.mp4").string();
  // the integrator's stability at the frame step, said once before starting
  if (const std::string w = palpate::integrator_warning(scene.value().lattice, 1.0 / 60.0); !w.empty())
    std::fprintf(stderr, "palpate: warning: %s\n", w.c_str());
  if (const std::string w = palpate::material_warning(scene.value()); !w.empty())
    std::fprintf(stderr, "palpate: warning: %s\n", w.c_str());
  if (!mode.empty()) {
    opt.override_mode = true;
    opt.mode = palpate::from_name<palpate::RunMode>(mode).value_or(palpate::RunMode::kLockstep);  // checked by the parser
  } else if (palpate::device_driver(scene.value(), opt.device) == palpate::DeviceDriver::kShm) {
    // a device in another process runs on its own wall clock: so does the recording, unless told otherwise
    opt.override_mode = true;
    opt.mode = palpate::RunMode::kRealtime;
  }
  const palpate::RunMode run_mode = opt.override_mode ? opt.mode : scene.value().run_mode;
  if (realtime_flags && run_mode == palpate::RunMode::kLockstep)
    std::fprintf(stderr, "palpate: warning: --spin-us and --priority apply to realtime recordings; this one is lockstep\n");
  // a realtime run encodes its default video after the run, from its frames: an encoder thread beside the servo
  // took its wake latency p99 from 60 us to 409 us (16 overruns in 4 s) on this 2-core machine
  const bool video_after = run_mode == palpate::RunMode::kRealtime && opt.video_optional && !opt.video_path.empty();
  const std::string video_after_path = video_after ? opt.video_path : std::string();
  if (video_after) opt.video_path.clear();
  // the live view listens before anything is recorded: an address in use leaves no output behind
  std::unique_ptr<palpate::LiveFeed> feed;
  std::unique_ptr<palpate::LiveServer> server;
  if (!serve.empty()) {
    auto address = palpate::parse_serve_address(serve);
    if (!address) {
      std::fprintf(stderr, "palpate: %s\n", address.error().message.c_str());
      return 2;
    }
    feed = std::make_unique<palpate::LiveFeed>(scene.value().render.width, scene.value().render.height, scene_path,
                                               run_mode == palpate::RunMode::kRealtime ? "realtime" : "lockstep");
    if (serve_linger_s > 0.0) feed->keep_frames();
    server = std::make_unique<palpate::LiveServer>(feed.get());
    if (auto st = server->start(address.value()); !st) {
      std::fprintf(stderr, "palpate: %s\n", st.error().message.c_str());
      return 2;
    }
    std::fprintf(stderr, "palpate: live view at %s\n", server->url().c_str());
    opt.live = feed.get();
  }
  auto res = palpate::record_scene(scene.value(), opt);
  if (!res) {
    std::fprintf(stderr, "palpate: %s\n", res.error().message.c_str());
    return 1;
  }
  auto& r = res.value();
  if (video_after && r.frames_written > 0) {
    auto made = palpate::make_recording_video(opt.out_dir, video_after_path, 60);
    nlohmann::json v;
    if (made) {
      r.video_path = made.value().path;
      v = {{"enabled", true}, {"made", "after the realtime run, from frames/"}, {"path", made.value().path},
           {"encoder", made.value().encoder}, {"frames", made.value().frames}, {"bytes", made.value().bytes}};
    } else {
      std::fprintf(stderr, "palpate: warning: no video: %s\n", made.error().message.c_str());
      v = {{"enabled", false}, {"reason", made.error().message}};
    }
    // the summary says what became of the video
    std::ifstream in(r.summary_path);
    nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
    in.close();
    if (!j.is_discarded()) {
      j["video"] = v;
      if (auto st = palpate::write_file_atomic(r.summary_path, j.dump(2) + "\n", "summary"); !st)
        std::fprintf(stderr, "palpate: %s\n", st.error().message.c_str());
    }
  }
  std::printf("frames   %s/frames/ (%d PNG)\n", opt.out_dir.c_str(), r.frames_written);
  if (!r.video_path.empty()) std::printf("video    %s\n", r.video_path.c_str());
  std::printf("log      %s/haptic.csv\n", opt.out_dir.c_str());
  std::printf("summary  %s\n", r.summary_path.c_str());
  if (!r.state_hash.empty()) std::printf("state_hash %s\n", r.state_hash.c_str());
  if (!r.no_contact.empty()) std::fprintf(stderr, "palpate: warning: %s\n", r.no_contact.c_str());
  std::fflush(stdout);
  if (server && serve_linger_s > 0.0) linger(*server, serve_linger_s);
  if (server) server->stop();
  // divergence is never silent: the outputs stay, the exit status says they hold a reset lattice (unless the
  // scene accepts it with lattice.allow_divergence: then a warning says the same)
  if (r.nan_events > 0 || r.divergence_events > 0) {
    const bool allowed = scene.value().lattice.allow_divergence;
    std::fprintf(stderr, "palpate: %sscene '%s': the lattice diverged: nan_events %lld, divergence_events %lld (see %s)%s\n",
                 allowed ? "warning: " : "", palpate::printable_text(scene_path).c_str(),
                 static_cast<long long>(r.nan_events), static_cast<long long>(r.divergence_events),
                 palpate::printable_text(r.summary_path).c_str(),
                 allowed ? "; accepted (lattice.allow_divergence)" : "");
    return allowed ? 0 : 1;
  }
  return 0;
}

// A command-line value the parser let through but that does not make sense: one line, exit 2.
int usage_error(const palpate::Error& e) {
  std::fprintf(stderr, "palpate: %s\n", e.message.c_str());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  // a file-size limit (ulimit -f) fails the write that crosses it with EFBIG, reported against that file like a
  // full disk, instead of killing the process with SIGXFSZ halfway through its outputs
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"palpate: feel and deform 3D models through a haptic device; headless recordings and loop-rate figures"};
  palpate::prefix_usage_errors(app, "palpate");
  app.require_subcommand(1);
  app.footer(palpate::kLimitsHelp);

  auto* rec = app.add_subcommand("record", "Record a scene: frames/*.png, haptic.csv, summary.json");
  rec->footer(palpate::kLimitsHelp);
  std::string scene_path, mode;
  palpate::RecordOptions opt;
  bool no_render = false;
  bool full_redraw = false;
  rec->add_option("scene", scene_path, "Scene file (JSON), e.g. scenes/bunny_pull.json")->required();
  rec->add_option("--out,-o", opt.out_dir, "Output folder (default: out/<scene name>)");
  rec->add_option("--mode", mode, "lockstep (reproducible, default of scenes) or realtime (wall clock)")
      ->check(CLI::IsMember({"lockstep", "realtime"}));
  rec->add_option("--duration", opt.duration_s, "Scene seconds to record (overrides the scene)")
      ->check(palpate::finite_range(1.0 / 60.0, 3600.0));
  rec->add_flag("--quiet,-q", opt.quiet, "No progress line");
  rec->add_flag("--no-render", no_render, "Simulate and log only: no GL, no frames");
  rec->add_flag("--full-redraw", full_redraw,
                "Draw the whole mesh every frame instead of a cached static layer plus what moves (same pixels)");
  rec->add_option("--device", opt.device, "Device: scripted | shm:NAME (palpate-device) | plugin:PATH.so | replay:PATH (haptic.csv or recording folder)");
  rec->add_option("--spin-us", opt.spin_us,
                  "realtime: spin this many us before each servo deadline (0 = sleep only; default: adaptive, the sleep's "
                  "p99 lateness + 10 us, at most 60 % of the period and 200 us)")
      ->check(CLI::Range(0, 1000));
  rec->add_option("--priority", opt.fifo_priority, "realtime: servo SCHED_FIFO priority (0 = normal scheduling)")
      ->check(CLI::Range(0, 99));
  rec->add_option("--servo-rate", opt.servo_rate_hz,
                  "Servo rate in Hz (lockstep: ticks per scene-second; default: the scene's servo.rate_hz, 1000); "
                  "device, servo period, passivity guard and the coupling's passivity bound 2b/T follow it")
      ->check(palpate::finite_range(palpate::kMinServoRate_hz, palpate::kMaxServoRate_hz));

  // video on by default: it costs the sim thread one frame copy (the encoder has its own thread); see README
  std::string video_path;
  bool no_video = false;
  rec->add_option("--video", video_path,
                  "Also encode the frames as H.264 MP4 (default on, at <out>/recording.mp4; an explicit FILE must be "
                  "writable, a missing encoder is then an error instead of a warning)")
      ->expected(0, 1);
  rec->add_flag("--no-video", no_video, "No MP4, frames/*.png only");
  std::string serve;
  double serve_linger_s = 0.0;
  rec->add_option("--serve", serve,
                  "Live view in a browser while recording: serve it on [ADDR:]PORT (ADDR default 127.0.0.1; PORT 0 = any "
                  "free port); the URL is printed on stderr");
  rec->add_option("--serve-linger", serve_linger_s,
                  "With --serve: keep the live view (last frame, final figures) up this many seconds after the run")
      ->check(palpate::finite_range(0.0, 86400.0));

  auto* vid = app.add_subcommand("video", "Make the MP4 (H.264, yuv420p) of a recording from its frames/frame_*.png");
  std::string vid_folder, vid_out;
  int vid_fps = 60;
  vid->add_option("folder", vid_folder, "Recording folder (holds frames/ and summary.json)")->required();
  vid->add_option("--out,-o", vid_out, "MP4 to write (default: FOLDER/recording.mp4)");
  vid->add_option("--fps", vid_fps, "Frames per second")->check(CLI::Range(1, 1000))->capture_default_str();

  auto* info = app.add_subcommand("info", "Mesh counts, box and grid hierarchy per level");
  std::string mesh_path;
  int levels = 5;
  bool json = false;
  info->add_option("mesh", mesh_path, "Mesh file (OBJ, PLY, STL, OFF, ...)")->required();
  info->add_option("--levels,-k", levels, "Grid levels (1..8)")->check(CLI::Range(1, 8));
  info->add_flag("--json", json, "Print JSON");

  auto* scn = app.add_subcommand("scene", "Write a touch, pull or cut scene that works on any mesh");
  palpate::SceneRequest srq;
  std::string scene_out, scene_mode = "touch", scene_at, scene_from, scene_up;
  const std::map<std::string, palpate::InteractionMode> modes{
      {"touch", palpate::InteractionMode::kTouch}, {"pull", palpate::InteractionMode::kPull},
      {"cut", palpate::InteractionMode::kCut}};
  scn->add_option("mesh", srq.mesh_path, "Mesh file (anything `palpate info` reads)")->required();
  scn->add_option("--mode", scene_mode, "touch (press), pull (grab and pull out) or cut (draw a blade across)")
      ->check(CLI::IsMember(modes))->capture_default_str();
  scn->add_option("--out,-o", scene_out, "Scene file to write (default: <mesh name>_<mode>.json here)");
  auto* at_opt = scn->add_option("--at", scene_at, "Work at the surface point nearest X,Y,Z (the mesh file's own "
                                 "coordinates, as `palpate info` prints its box)");
  scn->add_option("--from", scene_from, "Come in from this side, +x|-x|+y|-y|+z|-z (world, +z = up): the first surface "
                  "a ray from there through the model's centre meets (default +z)")->excludes(at_opt);
  scn->add_option("--depth-mm", srq.depth_mm, "Press / pull / cut depth in mm (default 10, pull 15)")
      ->check(CLI::Range(0.5, 50.0));
  scn->add_option("--level", srq.level, "Lattice level (default: sized to the model)")->check(CLI::Range(1, 8));
  scn->add_option("--up", scene_up, "The file's up axis (default: guessed from the model's extent)")
      ->check(CLI::IsMember({"x", "y", "z"}));

  // benchmarks: one sub-subcommand each
  auto* bench = app.add_subcommand("bench", "Benchmarks: figures as tables, JSON and plots");
  bench->require_subcommand(1);
  auto* bloop = bench->add_subcommand("loop", "Servo loop timing alone or beside the sim / record pipeline");
  palpate::BenchLoopOptions lo;
  bloop->add_option("--scene", lo.scene, "Scene whose device, model and pipeline are used")->capture_default_str();
  bloop->add_option("--rate", lo.rate_hz, "Servo rate in Hz")->check(palpate::finite_range(100.0, 50000.0))->capture_default_str();
  bloop->add_option("--seconds", lo.seconds, "Seconds per run")->check(palpate::finite_range(0.1, 3600.0))->capture_default_str();
  bloop->add_option("--load", lo.load, "none | sim | record")->check(CLI::IsMember({"none", "sim", "record"}))
      ->capture_default_str();
  bloop->add_option("--spin-us", lo.spin_us,
                    "Spin this many us before each deadline (default: adaptive, following how late the sleep returns)")
      ->check(CLI::Range(0, 1000));
  bloop->add_option("--spin-compare", lo.spin_compare, "Fixed windows (us) also run at each rate, side by side")
      ->delimiter(',')->check(CLI::Range(0, 1000));
  bloop->add_option("--priority", lo.priority, "SCHED_FIFO priority, 0 = normal scheduling")->check(CLI::Range(0, 99))
      ->capture_default_str();
  bloop->add_flag("--sweep", lo.sweep, "Try 1, 2, 5 and 10 kHz; report the highest rate such that it and every lower rate had no overruns");
  bloop->add_flag("--live", lo.live,
                  "With --load record: each run again with the live view served and a client fetching it as the page "
                  "does (rows side by side)");
  bloop->add_option("--json", lo.json_path, "Write the figures (with the latency histogram) as JSON");
  bloop->add_option("--plot", lo.plot_path, "Draw the wake-latency histogram (log-log) with gnuplot: FILE.png, "
                  "its data FILE.dat and script FILE.gp");

  auto* bforce = bench->add_subcommand("force", "Force between sim frames against a 1 kHz reference (per force model)");
  palpate::BenchForceOptions fo;
  bforce->add_option("scenes", fo.scenes, "Scenes to replay in lockstep")->capture_default_str();
  bforce->add_option("--json", fo.json_path, "Write the figures as JSON");

  auto* bsim = bench->add_subcommand("sim", "Speed against error per integrator x level x substeps/iterations (lockstep)");
  std::string bsim_scene;
  palpate::BenchSimOptions so;
  bsim->add_option("scene", bsim_scene, "Scene whose interaction is replayed, e.g. scenes/bunny_pull.json")->required();
  bsim->add_option("--json", so.json_path, "Write the rows as JSON");
  bsim->add_option("--plot", so.plot_path, "Plot node error against ms per frame (log axes, Pareto front) "
                 "with gnuplot: FILE.png, its data FILE.dat and script FILE.gp");
  bsim->add_option("--integrators", so.integrators, "Integrators to sweep (default: all)")->delimiter(',');
  bsim->add_option("--levels", so.levels, "Lattice levels to sweep (default: the scene's)")->delimiter(',')
      ->check(CLI::Range(1, palpate::kMaxGridLevels));
  bsim->add_option("--substeps", so.substeps, "Substeps per frame to sweep, 0 = automatic")->delimiter(',')
      ->check(CLI::Range(0, palpate::kMaxSubsteps))->capture_default_str();
  bsim->add_option("--iterations", so.iterations, "Newton / local-global iterations to sweep, 0 = default")
      ->delimiter(',')->check(CLI::Range(0, palpate::kMaxIterations))->capture_default_str();
  bsim->add_option("--ref-substeps", so.reference_substeps, "RK4 substeps per frame of the reference")
      ->check(CLI::Range(2, palpate::kMaxSubsteps))->capture_default_str();
  bsim->add_option("--duration", so.duration_s, "Scene seconds to replay (overrides the scene)")
      ->check(palpate::finite_range(1.0 / 60.0, 3600.0));
  bsim->add_option("--box", so.box_cells, "Box lattices of N cells per axis (powers of two) instead of the replay, "
                   "e.g. 4,8,16 = 125, 729, 4913 nodes")->delimiter(',')->check(CLI::Range(1, 128));
  bsim->add_flag("--quiet,-q", so.quiet, "No progress lines");

  auto* bscale = bench->add_subcommand(
      "scale", "Record a scene on its model subdivided 0..N times, cached layer beside full redraw (lockstep)");
  std::string bscale_scene = "scenes/bunny_pull.json";
  palpate::BenchScaleOptions sco;
  bscale->add_option("scene", bscale_scene, "Scene whose interaction is recorded")->capture_default_str();
  bscale->add_option("--max-subdivisions", sco.max_subdivisions,
                     "Largest midpoint subdivision (bunny: 0 = 3.7k, 1 = 14.7k, 2 = 58.8k, 3 = 235k, 4 = 940k triangles)")
      ->check(CLI::Range(0, 5))->capture_default_str();
  bscale->add_option("--duration", sco.duration_s, "Scene seconds to record (overrides the scene)")
      ->check(palpate::finite_range(1.0 / 60.0, 3600.0));
  bscale->add_flag("!--no-full", sco.full_redraw, "Skip the full-redraw runs beside the cached-layer ones");
  bscale->add_option("--json", sco.json_path, "Write the rows as JSON");
  bscale->add_option("--plot", sco.plot_path, "Plot ms per frame against triangles (log-log) with gnuplot: "
                   "FILE.png, its data FILE.dat and script FILE.gp");
  bscale->add_flag("--quiet,-q", sco.quiet, "No progress lines");

  auto* bmat = bench->add_subcommand("model", "Model error against closed-form continuum references per lattice level, "
                                              "each run to rest by the simulation, beside ms per frame");
  bmat->alias("material");
  palpate::BenchModelOptions mo;
  std::string mo_integrator = palpate::integrator_name(mo.integrator);
  bmat->add_option("--levels", mo.levels, "Lattice levels (the cantilever runs from 4)")->delimiter(',')
      ->check(CLI::Range(2, 7))->capture_default_str();
  bmat->add_option("--young-modulus", mo.young_modulus_Pa, "E in Pa")->check(palpate::finite_range(1.0, 1e12))->capture_default_str();
  bmat->add_option("--damping", mo.stiffness_damping_s, "Rayleigh beta in s (how fast the runs come to rest)")
      ->check(palpate::finite_range(0.0, 10.0))->capture_default_str();
  bmat->add_option("--references", mo.references, "Which references: compression, cantilever, hertz")->delimiter(',')
      ->capture_default_str();
  bmat->add_option("--integrator", mo_integrator, "Integrator that steps every run to rest")->capture_default_str();
  bmat->add_option("--poisson", mo.poisson_ratios, "Poisson ratios of the material.model 'volumetric' rows (none: "
                   "--poisson '')")->delimiter(',')->check(palpate::finite_range(0.0, 0.49))->capture_default_str();
  bmat->add_option("--large-strain", mo.large_strain_poisson_ratios, "Poisson ratios of the 30 % compression rows "
                   "(material.model 'neo_hookean'; none by default: the runs do not come to rest yet)")->delimiter(',')
      ->check(palpate::finite_range(0.0, 0.49))->capture_default_str();
  bmat->add_option("--poisson-level", mo.poisson_level, "Level of those rows' cantilever and Hertz")
      ->check(CLI::Range(4, 7))->capture_default_str();
  bmat->add_option("--json", mo.json_path, "Write the rows as JSON");
  bmat->add_option("--plot", mo.plot_path, "Plot force error against ms per frame (log-log) as PNG");

  auto* bpng = bench->add_subcommand("png", "PNG encoders side by side on a recording's frames (ms per frame, size, lossless check)");
  palpate::BenchPngOptions po;
  bpng->add_option("folder", po.folder, "Recording folder (frames/frame_*.png), e.g. out/bunny_pull (default with "
                   "--record: the last recording made)");
  bpng->add_option("--record", po.record, "Also record this lockstep scene with each frame writer (zlib RGBA / RGB, "
                   "libdeflate RGB, 1 and 2 threads) in turn, --reps times: wall per scene-second and state hashes");
  bpng->add_option("--out,-o", po.out_dir, "Folder for the --record recordings")->capture_default_str();
  bpng->add_option("--frames", po.frames, "Frames used, spread over the recording")->check(CLI::Range(1, 100000))
      ->capture_default_str();
  bpng->add_option("--reps", po.repetitions, "Passes over the frames")->check(CLI::Range(1, 1000))->capture_default_str();
  bpng->add_option("--json", po.json_path, "Write the rows as JSON");

  auto* bmesh = bench->add_subcommand("mesh", "Mesh loading with the reader in a child process against in this "
                                      "process, alternately (median and fastest ms, ratio)");
  palpate::BenchMeshOptions mso;
  bmesh->add_option("files", mso.files, "Valid mesh files (e.g. scenes/bunny.obj)")->required();
  bmesh->add_option("--reps", mso.repetitions, "Loads per way and file")->check(CLI::Range(1, 1000))
      ->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  if (*rec) {
    opt.render = !no_render;
    opt.full_redraw = full_redraw;
    const bool video_given = rec->get_option("--video")->count() > 0;
    if (video_given && no_video) {
      std::fprintf(stderr, "palpate: --video and --no-video exclude each other\n");
      return 2;
    }
    if (!no_video && !no_render) {
      // the default path is decided once the output folder is known (run_record)
      opt.video_path = video_path;
      opt.video_optional = video_path.empty();
    }
    if (video_given && no_render) std::fprintf(stderr, "palpate: warning: --video needs frames; --no-render records none\n");
    const bool want_video = !no_video && !no_render;
    const bool realtime_flags = rec->get_option("--spin-us")->count() > 0 || rec->get_option("--priority")->count() > 0;
    if (serve_linger_s > 0.0 && serve.empty()) {
      std::fprintf(stderr, "palpate: --serve-linger needs --serve\n");
      return 2;
    }
    return run_record(scene_path, opt, mode, realtime_flags, want_video, serve, serve_linger_s);
  }
  if (*vid) {
    auto made = palpate::make_recording_video(vid_folder, vid_out, vid_fps);
    if (!made) {
      std::fprintf(stderr, "palpate: %s\n", made.error().message.c_str());
      return 1;
    }
    const auto& m = made.value();
    std::printf("video    %s (%lld frames, %s, %lld bytes)\n", m.path.c_str(), static_cast<long long>(m.frames),
                m.encoder.c_str(), static_cast<long long>(m.bytes));
    return 0;
  }
  if (*info) return palpate::run_info(mesh_path, levels, json);
  if (*scn) {
    srq.mode = modes.at(scene_mode);
    if (!scene_up.empty()) srq.up_axis = scene_up[0];
    if (!scene_at.empty()) {
      auto p = palpate::parse_point("--at", scene_at);
      if (!p) return usage_error(p.error());
      srq.at_raw = p.value();
    }
    if (!scene_from.empty()) {
      auto d = palpate::parse_direction("--from", scene_from);
      if (!d) return usage_error(d.error());
      srq.from = d.value();
    }
    return palpate::run_scene(srq, scene_out);
  }
  // the benchmarks' default scenes are found from any folder, not only the repository root
  if (*bloop && bloop->get_option("--scene")->count() == 0) lo.scene = palpate::locate_default(lo.scene);
  if (*bforce && bforce->get_option("scenes")->count() == 0)
    for (auto& s : fo.scenes) s = palpate::locate_default(s);
  if (*bscale && bscale->get_option("scene")->count() == 0) bscale_scene = palpate::locate_default(bscale_scene);
  if (*bloop) return palpate::run_bench_loop(lo);
  if (*bforce) return palpate::run_bench_force(fo);
  if (*bmat && !palpate::integrator_from_name(mo_integrator, &mo.integrator)) {
    std::fprintf(stderr, "palpate: bench model: --integrator '%s' is not one of: explicit_euler, symplectic_euler, "
                 "implicit_euler, local_global, rk4\n", mo_integrator.c_str());
    return 2;
  }
  if (*bscale || *bmat || *bsim || *bpng || *bmesh) {
    // the table (and any JSON) first; the plot is drawn after, so a missing gnuplot loses neither
    palpate::PlotSpec plot;
    std::string plot_path;
    palpate::Result<std::string> table = std::string();
    if (*bscale) {
      table = palpate::run_bench_scale(bscale_scene, sco, &plot);
      plot_path = sco.plot_path;
    } else if (*bmat) {
      table = palpate::run_bench_model(mo, &plot);
      plot_path = mo.plot_path;
    } else if (*bpng) {
      table = palpate::run_bench_png(po);
    } else if (*bmesh) {
      table = palpate::run_bench_mesh(mso);
    } else if (so.box_cells.empty()) {
      table = palpate::run_bench_sim(bsim_scene, so, &plot);
      plot_path = so.plot_path;
    } else {
      table = palpate::run_bench_sim_box(bsim_scene, so);
    }
    if (!table) {
      std::fprintf(stderr, "palpate: %s\n", table.error().message.c_str());
      return 1;
    }
    std::fputs(table.value().c_str(), stdout);
    return plot_path.empty() ? 0 : palpate::write_plot_and_report(plot, plot_path);
  }
  return 2;
}
