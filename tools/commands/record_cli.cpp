#include "tools/commands/record_cli.h"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <memory>
#include <string>
#include <thread>

#include "core/limits.h"
#include "core/printable.h"
#include "core/scene.h"
#include "tools/commands/cli_checks.h"
#include "runtime/live/live_feed.h"
#include "runtime/live/live_server.h"
#include "runtime/record/record_plan.h"
#include "runtime/record/material_report.h"
#include "runtime/record/recorder.h"

namespace palpate {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;

// Ctrl-C, SIGTERM or SIGHUP (a dropped SSH session) during a recording: the run ends after the frame under way and
// every output is finished
// (frames, haptic.csv, summary.json "interrupted"). A second signal a second or more after the first ends the
// process at once; one sooner is the same request again (`timeout` passes a signal to its command and to the
// command's process group, so the command gets it twice)
std::atomic<bool> g_stop_recording{false};
std::atomic<int64_t> g_first_stop_ns{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int64_t>::is_always_lock_free,
              "a signal handler sets them");
extern "C" void on_record_signal(int sig) {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);  // async-signal-safe
  const int64_t now_ns = static_cast<int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
  int64_t first = 0;
  if (g_first_stop_ns.compare_exchange_strong(first, now_ns, std::memory_order_relaxed)) {
    g_stop_recording.store(true, std::memory_order_relaxed);
  } else if (now_ns - first >= 1'000'000'000) {
    signal(sig, SIG_DFL);
    raise(sig);
  }
}

// Installs on_record_signal for SIGINT, SIGTERM and SIGHUP for its lifetime.
class StopOnSignal {
 public:
  StopOnSignal() {
    struct sigaction sa {};
    sa.sa_handler = on_record_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
    sigaction(SIGHUP, &sa, &old_hup_);
  }
  ~StopOnSignal() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
    sigaction(SIGHUP, &old_hup_, nullptr);
  }
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;

 private:
  struct sigaction old_int_ {}, old_term_ {}, old_hup_ {};
};

// The command line of `palpate record`, as parsed.
struct RecordArgs {
  std::string scene_path, mode, video_path, serve, color, antialias;
  RecordOptions opt;
  bool no_render = false, no_video = false, no_arrow = false, no_legend = false, no_floor = false, no_trace = false;
  double color_range_m = 0.0;
  double serve_linger_s = 0.0;
};

// Keeps the live view up after the run for linger_s seconds, or until Ctrl-C / SIGTERM.
void linger(const LiveServer& server, double linger_s) {
  std::fprintf(stderr, "palpate: live view: the run is over; serving its last frame at %s for %.0f s (Ctrl-C ends)\n",
               server.url().c_str(), linger_s);
  auto on_signal = [](int) { g_interrupted = 1; };
  struct sigaction sa {}, old_int {}, old_term {}, old_hup {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &old_int);
  sigaction(SIGTERM, &sa, &old_term);
  sigaction(SIGHUP, &sa, &old_hup);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(linger_s);
  while (!g_interrupted && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  sigaction(SIGHUP, &old_hup, nullptr);
}

// What was written, one line each (only what exists).
void print_outputs(const RecordPlan& plan, const RecordResult& r) {
  if (plan.render)
    std::printf("frames   %s/ (%d PNG)\n", plan.frames_dir.c_str(), r.frames_written);
  if (!r.video_path.empty()) std::printf("video    %s\n", r.video_path.c_str());
  std::printf("log      %s\n", plan.haptic_csv_path.c_str());
  std::printf("summary  %s\n", r.summary_path.c_str());
  if (!r.state_hash.empty()) std::printf("state_hash %s\n", r.state_hash.c_str());
  // what the material became and how far its contact is from the continuum, by the bench's calibration
  const nlohmann::json summary = nlohmann::json::parse(r.summary_json, nullptr, false);
  if (summary.is_object() && summary.contains("material"))
    if (const std::string m = material_line(summary["material"]); !m.empty()) std::printf("material %s\n", m.c_str());
  std::fflush(stdout);
}

int run_record(const CLI::App& cmd, RecordArgs& a) {
  RecordOptions& opt = a.opt;
  if (cmd.get_option("--video")->count() > 0 && a.no_video) {
    std::fprintf(stderr, "palpate: --video and --no-video exclude each other\n");
    return 2;
  }
  if (cmd.get_option("--serve")->count() > 0 && a.serve.empty()) {
    std::fprintf(stderr, "palpate: --serve '': give [ADDR:]PORT (e.g. 8080, or 0 for any free port)\n");
    return 2;
  }
  if (a.serve_linger_s > 0.0 && a.serve.empty()) {
    std::fprintf(stderr, "palpate: --serve-linger needs --serve\n");
    return 2;
  }
  opt.render = !a.no_render;
  // video on by default (<out>/recording.mp4, a warning when it cannot be made); an explicit FILE must be made
  if (!a.no_video) {
    opt.video_path = a.video_path;
    opt.video_optional = a.video_path.empty();
  }
  if (!a.mode.empty()) {
    opt.override_mode = true;
    opt.mode = from_name<RunMode>(a.mode).value_or(RunMode::kLockstep);  // checked by the parser
  }
  opt.realtime_flags = cmd.get_option("--spin-us")->count() > 0 || cmd.get_option("--priority")->count() > 0;

  auto scene = load_scene(a.scene_path);
  if (!scene) {
    std::fprintf(stderr, "palpate: %s\n", scene.error().message.c_str());
    return 1;
  }
  report_scene_warnings(scene.value(), stderr);
  // what the frames show besides the model (the scene's render.color, color_range_m, force_arrow, legend)
  RenderSpec& look = scene.value().render;
  if (!a.color.empty()) look.color = from_name<RenderColor>(a.color).value_or(RenderColor::kAuto);
  if (colors_by_strain(scene.value()) && scene.value().mode == InteractionMode::kCut) {
    std::fprintf(stderr, "palpate: %s\n", kStrainInCut);
    return 1;
  }
  if (cmd.get_option("--color-range")->count() > 0)
    (colors_by_strain(scene.value()) ? look.strain_range : look.color_range_m) = a.color_range_m;
  if (a.no_arrow) look.force_arrow = false;
  if (a.no_legend) look.legend = false;
  if (a.no_floor) look.floor = false;
  if (a.no_trace) look.force_trace = false;
  if (!a.antialias.empty())
    look.antialias = a.antialias == "edges" ? kAntialiasEdges : a.antialias == "none" ? 0 : std::stoi(a.antialias);
  // everything decided and every output checked before anything in the output folder is touched
  auto planned = plan_record(scene.value(), opt);
  if (!planned) {
    std::fprintf(stderr, "palpate: %s\n", planned.error().message.c_str());
    return 1;
  }
  const RecordPlan& plan = planned.value();
  if (auto st = check_plan_outputs(plan); !st) {
    std::fprintf(stderr, "palpate: %s\n", st.error().message.c_str());
    return 1;
  }
  if (plan.driver == DeviceDriver::kBrowser && a.serve.empty()) {
    std::fprintf(stderr, "palpate: --device browser: the live page is the device; give --serve [ADDR:]PORT (e.g. "
                         "--serve 8080, then open http://127.0.0.1:8080/)\n");
    return 2;
  }
  for (const std::string& w : plan.warnings) std::fprintf(stderr, "palpate: warning: %s\n", w.c_str());
  // the live view listens before anything is recorded: an address in use leaves no output behind
  // the link outlives the server and the recording that both use it
  std::unique_ptr<BrowserLink> browser;
  std::unique_ptr<LiveFeed> feed;
  std::unique_ptr<LiveServer> server;
  if (plan.driver == DeviceDriver::kBrowser) {
    browser = std::make_unique<BrowserLink>();
    opt.browser = browser.get();
  }
  if (!a.serve.empty()) {
    auto address = parse_serve_address(a.serve);
    if (!address) {
      std::fprintf(stderr, "palpate: %s\n", address.error().message.c_str());
      return 2;
    }
    feed = std::make_unique<LiveFeed>(plan.scene.render.width, plan.scene.render.height, a.scene_path,
                                      plan.lockstep ? "lockstep" : "realtime");
    if (a.serve_linger_s > 0.0) feed->keep_frames();
    feed->set_out_dir(plan.out_dir);
    server = std::make_unique<LiveServer>(feed.get(), browser.get());
    server->set_browser_timing(1e3 * browser_params(plan.scene).watchdog_s(), plan.scene.device.browser_send_ms);
    server->set_browser_scene(&plan.scene);
    if (auto st = server->start(address.value()); !st) {
      std::fprintf(stderr, "palpate: %s\n", st.error().message.c_str());
      return 2;
    }
    std::fprintf(stderr, "palpate: live view at %s\n", server->url().c_str());
    if (!server->token().empty())
      std::fprintf(stderr, "palpate: the live view listens beyond loopback: from another machine open "
                           "http://ADDRESS:%d/?token=%s (ADDRESS: this machine's IP address or name); a page "
                           "without the token watches but cannot steer\n", server->port(), server->token().c_str());
    opt.live = feed.get();
  }
  Result<RecordResult> res = Error{};
  {
    const StopOnSignal stop_on_signal;
    opt.stop = &g_stop_recording;
    res = record_planned(plan, opt);
  }
  if (!res) {
    std::fprintf(stderr, "palpate: %s\n", res.error().message.c_str());
    return 1;
  }
  const RecordResult& r = res.value();
  if (!r.mesh_notice.empty())
    std::fprintf(stderr, "palpate: mesh '%s': %s\n", printable_text(plan.scene.mesh.file).c_str(), r.mesh_notice.c_str());
  print_outputs(plan, r);
  // 128 + SIGINT, as shells report a command ended by Ctrl-C
  if (!r.interrupted.empty()) {
    std::fprintf(stderr, "palpate: %s\n", r.interrupted.c_str());
    if (server) server->stop();
    return 130;
  }
  if (!r.no_contact.empty()) std::fprintf(stderr, "palpate: warning: %s\n", r.no_contact.c_str());
  if (!r.tool_inside.empty())
    std::fprintf(stderr, "palpate: warning: %s (see %s, tool_inside)\n", r.tool_inside.c_str(),
                 printable_text(r.summary_path).c_str());
  if (server && a.serve_linger_s > 0.0) linger(*server, a.serve_linger_s);
  if (server) server->stop();
  // divergence is never silent: the outputs stay, the exit status says they hold a reset lattice (unless the
  // scene accepts it with lattice.allow_divergence: then a warning says the same)
  if (r.nan_events > 0 || r.divergence_events > 0) {
    const bool allowed = plan.scene.lattice.allow_divergence;
    // a Neo-Hookean lattice torn by its push: its steps were taken again to convergence and still stretched a spring
    // past 11 times its length, so the push asks more than the material holds on these cells
    const bool torn_solid = plan.scene.lattice.material.enabled && plan.scene.lattice.material.model == MaterialModel::kNeoHookean &&
                            r.divergence_events > 0;
    std::fprintf(stderr, "palpate: %sscene '%s': the lattice diverged: nan_events %lld, divergence_events %lld (each "
                 "reset the lattice to rest: a value not finite, or a spring past 11 times its length) (see %s)%s%s\n",
                 allowed ? "warning: " : "", printable_text(a.scene_path).c_str(), static_cast<long long>(r.nan_events),
                 static_cast<long long>(r.divergence_events), printable_text(r.summary_path).c_str(),
                 torn_solid ? "; the push tore the Neo-Hookean solid (its steps taken again to convergence stretched it "
                              "as far): material.model 'volumetric', a stiffer material, a larger tool or a lower "
                              "device.max_force_N keep it whole"
                            : "",
                 allowed ? "; accepted (lattice.allow_divergence)" : "");
    return allowed ? 0 : 1;
  }
  return 0;
}

}  // namespace

Subcommand add_record_command(CLI::App& app) {
  auto a = std::make_shared<RecordArgs>();
  RecordOptions& opt = a->opt;
  auto* rec = app.add_subcommand("record", "Record a scene: frames/*.png, recording.mp4, haptic.csv, summary.json");
  rec->footer("Limits of inputs: palpate --help");
  rec->add_option("scene", a->scene_path, "Scene file (JSON), e.g. scenes/bunny_pull.json")->required();
  rec->add_option("--out,-o", opt.out_dir, "Output folder (default: out/<scene name>)");
  rec->add_option("--mode", a->mode, "lockstep (reproducible, default of scenes) or realtime (wall clock)")
      ->check(CLI::IsMember({"lockstep", "realtime"}));
  rec->add_option("--duration", opt.duration_s, "Scene seconds to record (overrides the scene)")
      ->check(finite_range(Rates{}.frame_period_s(), 3600.0));
  rec->add_flag("--quiet,-q", opt.quiet, "No progress line");
  rec->add_flag("--no-render", a->no_render, "Simulate and log only: no GL, no frames");
  rec->add_flag("--full-redraw", opt.full_redraw,
                "Draw the whole mesh every frame instead of a cached static layer plus what moves (same pixels)");
  rec->add_option("--device", opt.device,
                  "Device: scripted | shm:NAME (palpate-device) | plugin:PATH.so | replay:PATH (haptic.csv or recording folder) | "
                  "browser (the --serve page's pointer steers the tool; realtime)");
  rec->add_option("--spin-us", opt.spin_us,
                  "realtime: spin this many us before each servo deadline (0 = sleep only; default: adaptive, the sleep's "
                  "p99 lateness + 10 us, at most 60 % of the period and 200 us)")
      ->check(CLI::Range(0, 1000));
  rec->add_option("--priority", opt.fifo_priority, "realtime: servo SCHED_FIFO priority (0 = normal scheduling)")
      ->check(CLI::Range(0, 99));
  rec->add_option("--servo-rate", opt.servo_rate_hz,
                  "Servo rate in Hz (lockstep: ticks per scene-second; default: the scene's servo.rate_hz); device, "
                  "servo period, passivity guard and the coupling's passivity bound 2b/T follow it")
      ->check(finite_range(kMinServoRate_hz, kMaxServoRate_hz));
  // video on by default: it costs the sim thread one frame copy (the encoder has its own thread)
  rec->add_option("--video", a->video_path,
                  "Also encode the frames as H.264 MP4 (default on, at <out>/recording.mp4; an explicit FILE must be "
                  "writable, a missing encoder is then an error instead of a warning)")
      ->expected(0, 1);
  rec->add_flag("--no-video", a->no_video, "No MP4, frames/*.png only");
  rec->add_option("--color", a->color,
                  "The surface's colour: displacement (from rest, its scale in the legend), strain (the lattice's "
                  "equivalent strain; touch and pull), none, or auto (displacement in touch and pull, none in cut; "
                  "the scene's render.color, default auto)")
      ->check(CLI::IsMember({"auto", "displacement", "strain", "none"}));
  rec->add_option("--color-range", a->color_range_m,
                  "The colour map's top: a displacement in metres, or with --color strain a strain (0.05 = 5 %) "
                  "(default: the scene's render.color_range_m or render.strain_range, else a first pass of a "
                  "scripted run finds it)")
      ->check(finite_range(1e-9, 100.0));
  rec->add_flag("--no-arrow", a->no_arrow, "No force arrow at the proxy (render.force_arrow)");
  rec->add_flag("--no-legend", a->no_legend, "No legend (render.legend)");
  rec->add_flag("--no-floor", a->no_floor, "No floor under the model, and no shadows (render.floor)");
  rec->add_flag("--no-trace", a->no_trace, "No inset of the force over the last two seconds (render.force_trace)");
  rec->add_option("--antialias", a->antialias,
                  "Anti-aliased edges (render.antialias): edges (the default: smoothed in the image, where it changed), "
                  "none, or 2, 4 or 8 samples a pixel (multisampled: four times the render time on llvmpipe)")
      ->check(CLI::IsMember({"edges", "none", "0", "2", "4", "8"}));
  rec->add_option("--serve", a->serve,
                  "Live view in a browser while recording: serve it on [ADDR:]PORT (ADDR default 127.0.0.1; PORT 0 = any "
                  "free port); the URL is printed on stderr");
  rec->add_option("--serve-linger", a->serve_linger_s,
                  "With --serve: keep the live view (last frame, final figures) up this many seconds after the run")
      ->check(finite_range(0.0, 86400.0));
  return {rec, [rec, a] { return run_record(*rec, *a); }};
}

}  // namespace palpate
