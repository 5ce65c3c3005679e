// palpate-device: the emulated hand device in its own process, served through the shared-memory shim at its
// own 1 kHz clock — device-in-the-loop across a real process boundary, as a bridge to a real device would be.

#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "tools/commands/cli_checks.h"

#include "core/scene.h"
#include "haptics/devices/replay_device.h"
#include "tools/device/device_server.h"

namespace {

std::atomic<bool> g_stop{false};

extern "C" void on_signal(int) { g_stop.store(true, std::memory_order_relaxed); }

void print_hist(const char* what, const palpate::LatencyHistogram& h) {
  std::printf("  %-34s p50 %6.0f  p99 %6.0f  p99.9 %6.0f  max %8.1f us  (n %lld)\n", what, h.quantile_us(0.5),
              h.quantile_us(0.99), h.quantile_us(0.999), h.max_us(), static_cast<long long>(h.count()));
}

}  // namespace

int main(int argc, char** argv) {
  static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler sets an atomic flag");
  CLI::App app{"palpate-device: the emulated hand device served through the shared-memory shim (stop: Ctrl-C)"};
  palpate::prefix_usage_errors(app, "palpate-device");
  palpate::DeviceServerOptions o;
  std::string scene_path, recording, inject;
  app.add_option("--name,-n", o.name, "Link name: palpate record SCENE --device shm:NAME")->required();
  app.add_option("--scene,-s", scene_path, "Scene whose trajectory, hand and device limits are used");
  app.add_option("--recording,-r", recording, "Follow the tool path of a recording (haptic.csv or its folder)");
  app.add_option("--duration", o.duration_s, "Stop after this many seconds (default: run until SIGINT/SIGTERM)")
      ->check(palpate::finite_range(0.0, 1e6));
  app.add_option("--rate", o.rate_hz, "Device clock in Hz")->check(palpate::finite_range(100.0, 20000.0))->capture_default_str();
  app.add_option("--sim-watchdog-ms", o.sim_watchdog_ms, "Sim silent this long -> release the force")
      ->check(palpate::finite_range(0.5, 10000.0))->capture_default_str();
  app.add_option("--release-ms", o.release_ms, "Force ramp to zero (and back in) time")
      ->check(palpate::finite_range(0.0, 10000.0))->capture_default_str();
  app.add_option("--log", o.log_path, "Write one CSV row per device tick (pose, force commanded and applied)");
  app.add_option("--inject", inject, "Test faults: bad poses to publish, e.g. nan@0.3,outside@0.5,jump@0.7");
  app.add_flag("--quiet,-q", o.quiet, "No event lines");
  int priority = 70;
  app.add_option("--priority", priority, "SCHED_FIFO priority of the device clock, 0 = normal scheduling")
      ->check(CLI::Range(0, 99))->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  if (scene_path.empty() && recording.empty()) {
    std::fprintf(stderr, "palpate-device: give --scene or --recording (where the hand goes)\n");
    return 2;
  }
  if (!scene_path.empty()) {
    auto scene = palpate::load_scene(scene_path);
    if (!scene) {
      std::fprintf(stderr, "palpate-device: %s\n", scene.error().message.c_str());
      return 1;
    }
    palpate::report_scene_warnings(scene.value(), stderr);
    o.hand = scene.value().hand;
    o.trajectory = scene.value().trajectory;
    o.max_force_N = scene.value().device.max_force_N;
    o.workspace_half_m = scene.value().device.workspace_half_m;
  }
  if (!recording.empty()) {
    auto rows = palpate::load_haptic_csv(recording);
    if (!rows) {
      std::fprintf(stderr, "palpate-device: %s\n", rows.error().message.c_str());
      return 1;
    }
    o.trajectory.clear();
    const double t0 = rows.value().front().t_s;
    for (const auto& r : rows.value()) o.trajectory.push_back({r.t_s - t0, r.pos_m, (r.buttons & 1u) != 0});
  }
  if (!inject.empty()) {
    auto f = palpate::parse_faults(inject);
    if (!f) {
      std::fprintf(stderr, "palpate-device: %s\n", f.error().message.c_str());
      return 2;
    }
    o.faults = f.value();
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);

  // the device clock: SCHED_FIFO and locked memory where allowed; said once when refused
  std::string refused;
  if (priority > 0) {
    sched_param sp{};
    sp.sched_priority = priority;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) != 0) refused += std::string("SCHED_FIFO: ") + std::strerror(errno);
    if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
      refused += std::string(refused.empty() ? "" : "; ") + "mlockall: " + std::strerror(errno);
  }
  prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  if (!refused.empty()) std::printf("palpate-device: refused: %s; running with normal priority\n", refused.c_str());
  std::printf("palpate-device: serving shm '%s' (/dev/shm/palpate-%s) at %.0f Hz, %zu keyframes from %s; "
              "stop with Ctrl-C\n",
              o.name.c_str(), o.name.c_str(), o.rate_hz, o.trajectory.size(),
              recording.empty() ? scene_path.c_str() : recording.c_str());
  std::fflush(stdout);
  auto rep = palpate::run_device_server(o, g_stop);
  if (!rep) {
    std::fprintf(stderr, "palpate-device: %s\n", rep.error().message.c_str());
    return 1;
  }
  const auto& r = rep.value();
  std::printf("palpate-device: stopped after %lld ticks (%.3f s); timing:\n", static_cast<long long>(r.ticks),
              static_cast<double>(r.ticks) / o.rate_hz);
  print_hist("wake latency", r.wake_latency);
  print_hist("pose -> force written by the sim", r.pose_to_force);
  print_hist("pose -> force seen here (round trip)", r.round_trip);
  std::printf("  overruns %lld; forces received %lld (refused: non-finite or past the maximum %lld); sim connected %lld, lost %lld; "
              "max force applied %.3f N\n",
              static_cast<long long>(r.overruns), static_cast<long long>(r.forces),
              static_cast<long long>(r.rejected_forces), static_cast<long long>(r.sim_found),
              static_cast<long long>(r.sim_lost), r.max_force_applied_N);
  return 0;
}
