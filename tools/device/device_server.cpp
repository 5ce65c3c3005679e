#include "tools/device/device_server.h"

#include "core/atomic_file.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "core/clock.h"
#include "haptics/devices/device_link.h"
#include "haptics/devices/scripted_device.h"
#include "haptics/devices/shm_segment.h"

namespace palpate {

Result<std::vector<InjectedFault>> parse_faults(const std::string& text) {
  std::vector<InjectedFault> out;
  std::istringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    const auto at = item.find('@');
    InjectedFault f;
    const std::string kind = item.substr(0, at);
    if (kind == "nan") f.kind = InjectedFault::Kind::kNonFinite;
    else if (kind == "outside") f.kind = InjectedFault::Kind::kOutside;
    else if (kind == "jump") f.kind = InjectedFault::Kind::kJump;
    else return make_error("--inject '", item, "': unknown fault (nan, outside, jump)");
    char* end = nullptr;
    const std::string t = at == std::string::npos ? "" : item.substr(at + 1);
    f.t_s = std::strtod(t.c_str(), &end);
    if (t.empty() || *end != '\0' || !(f.t_s >= 0.0)) return make_error("--inject '", item, "': expected KIND@SECONDS");
    out.push_back(f);
  }
  return out;
}

Result<DeviceServerReport> run_device_server(const DeviceServerOptions& o, const std::atomic<bool>& stop) {
  palpate_shim_specs specs{};
  specs.max_force_N = o.max_force_N;
  specs.max_stiffness_N_per_m = 700.0;
  specs.workspace_half_m = o.workspace_half_m;
  specs.rate_hz = o.rate_hz;
  auto seg_r = ShmSegment::serve(o.name, specs);
  if (!seg_r) return seg_r.error();
  palpate_shim_segment* seg = seg_r.value().get();

  std::FILE* log = nullptr;
  AtomicFile log_file;
  std::vector<char> log_buf(1 << 20);
  if (!o.log_path.empty()) {
    auto f = AtomicFile::open(o.log_path, "log", ".partial");
    if (!f) return f.error();
    log_file = std::move(f).value();
    log = log_file.stream();
    std::setvbuf(log, log_buf.data(), _IOFBF, log_buf.size());
    std::fputs("tick,t_s,pos_x_m,pos_y_m,pos_z_m,buttons,cmd_x_N,cmd_y_N,cmd_z_N,force_x_N,force_y_N,force_z_N,gain,sim_alive\n", log);
  }

  DeviceSpecs ds;
  ds.max_force_N = o.max_force_N;
  ds.workspace_half_m = o.workspace_half_m;
  ds.rate_hz = o.rate_hz;
  ScriptedDevice hand(ds, o.hand, o.trajectory);
  DeviceServerReport rep;
  const int64_t period_ns = static_cast<int64_t>(std::llround(1e9 / o.rate_hz));
  PeerWatchdog sim_hb(static_cast<int64_t>(o.sim_watchdog_ms * 1e6));
  PeerWatchdog sim_force(static_cast<int64_t>(o.sim_watchdog_ms * 1e6));
  ForceRamp gain(static_cast<int64_t>(o.release_ms * 1e6));
  gain.reset(0.0, monotonic_ns());
  Vec3 cmd_N = Vec3::Zero();
  uint64_t force_seq = __atomic_load_n(&seg->force.force.seq, __ATOMIC_ACQUIRE);
  uint64_t pose_seq = __atomic_load_n(&seg->pose.pose.seq, __ATOMIC_ACQUIRE);
  bool sim_alive = false;
  double traj_t0_s = -1.0;

  __atomic_store_n(&seg->header.device_state, uint64_t{PALPATE_SHIM_DEVICE_RUNNING}, __ATOMIC_RELEASE);
  const int64_t t0_ns = monotonic_ns() + period_ns;
  int64_t next_ns = t0_ns;
  bool lost = false;
  while (!stop.load(std::memory_order_relaxed)) {
    // the segment shrunk under us by another process: what we write is seen by nobody
    if (seg_r.value().lost()) {
      lost = true;
      break;
    }
    sleep_until_ns(next_ns);
    const int64_t now = monotonic_ns();
    rep.wake_latency.add(now - next_ns);
    const double t_s = static_cast<double>(next_ns - t0_ns) * 1e-9;
    if (o.duration_s > 0.0 && t_s >= o.duration_s) break;

    // the sim: alive while both its heartbeat and its force counter move
    const bool hb_ok = sim_hb.update(palpate_shim_beats(&seg->sim_hb), now);
    palpate_shim_force f{};
    if (palpate_shim_read_force(&seg->force, &f, 4) && f.seq != force_seq) {
      force_seq = f.seq;
      ++rep.forces;
      const Vec3 in(f.force_N[0], f.force_N[1], f.force_N[2]);
      // the sim clamps to at most this device's maximum: a command beyond it (or non-finite) is garbage in the
      // slot, not a force to render at full strength
      if (!in.allFinite() || in.norm() > o.max_force_N * (1.0 + 1e-9)) {
        ++rep.rejected_forces;
        cmd_N.setZero();
      } else {
        cmd_N = in;
      }
      if (f.pose_seq != 0 && f.pose_time_ns > 0 && f.pose_time_ns <= now) {
        rep.round_trip.add(now - f.pose_time_ns);
        if (f.time_ns >= f.pose_time_ns) rep.pose_to_force.add(f.time_ns - f.pose_time_ns);
      }
    }
    const bool force_ok = sim_force.update(force_seq, now);
    const bool alive = hb_ok && force_ok;
    if (alive != sim_alive) {
      sim_alive = alive;
      ++(alive ? rep.sim_found : rep.sim_lost);
      if (!o.quiet) {
        if (alive) std::printf("palpate-device: sim connected at device tick %lld\n", static_cast<long long>(rep.ticks));
        else std::printf("palpate-device: sim silent at device tick %lld: releasing force over %.0f ms\n",
                         static_cast<long long>(rep.ticks), o.release_ms);
        std::fflush(stdout);
      }
    }
    // a silent sim's last command is never held: it ramps to zero
    const double g = gain.update(alive ? 1.0 : 0.0, now);
    const Vec3 applied_N = g * cmd_N;
    rep.max_force_applied_N = std::max(rep.max_force_applied_N, applied_N.norm());
    hand.write_force(applied_N);
    // the trajectory starts when the first sim connects (a two-terminal session starts the device first)
    if (alive && traj_t0_s < 0.0) traj_t0_s = t_s;
    DevicePose pose;
    hand.read(traj_t0_s < 0.0 ? 0.0 : t_s - traj_t0_s, &pose);

    palpate_shim_pose p{};
    p.seq = ++pose_seq;
    p.time_ns = monotonic_ns();
    for (int i = 0; i < 3; ++i) p.pos_m[i] = pose.pos_m[i];
    p.quat_wxyz[0] = pose.orientation.w();
    p.quat_wxyz[1] = pose.orientation.x();
    p.quat_wxyz[2] = pose.orientation.y();
    p.quat_wxyz[3] = pose.orientation.z();
    p.buttons = pose.buttons;
    for (std::size_t k = 0; k < o.faults.size(); ++k) {
      // held for 5 ms, so a sim that samples between two device ticks still sees it
      const double since_s = t_s - traj_t0_s - o.faults[k].t_s;
      if (traj_t0_s < 0.0 || since_s < 0.0 || since_s >= 0.005) continue;
      switch (o.faults[k].kind) {
        case InjectedFault::Kind::kNonFinite: p.pos_m[1] = std::nan(""); break;
        case InjectedFault::Kind::kOutside: p.pos_m[0] = 2.0 * o.workspace_half_m; break;
        case InjectedFault::Kind::kJump: p.pos_m[2] += 0.05; break;  // 5 cm in one tick: 50 m/s
      }
      break;
    }
    palpate_shim_write_pose(&seg->pose, &p);
    palpate_shim_beat(&seg->device_hb, now);

    if (log)
      std::fprintf(log, "%lld,%.6f,%.9g,%.9g,%.9g,%u,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.4f,%d\n",
                   static_cast<long long>(rep.ticks), t_s, pose.pos_m.x(), pose.pos_m.y(), pose.pos_m.z(), pose.buttons,
                   cmd_N.x(), cmd_N.y(), cmd_N.z(), applied_N.x(), applied_N.y(), applied_N.z(), g, alive ? 1 : 0);
    ++rep.ticks;
    // absolute deadlines; periods already missed are skipped whole and counted
    next_ns += period_ns;
    const int64_t after = monotonic_ns();
    if (after > next_ns + period_ns) {
      const int64_t missed = (after - next_ns) / period_ns;
      rep.overruns += missed;
      next_ns += missed * period_ns;
    }
  }

  // stopped: say so in the segment; leave the name to a sim still attached (it removes it when it closes)
  __atomic_store_n(&seg->header.device_state, uint64_t{PALPATE_SHIM_DEVICE_STOPPED}, __ATOMIC_RELEASE);
  if (!sim_alive) ShmSegment::unlink(o.name);
  if (log) {
    if (auto st = log_file.commit(/*keep_partial=*/true); !st) return st.error();
  }
  if (lost)
    return make_error("shm '", o.name, "': the segment was truncated by another process at device tick ",
                      std::to_string(rep.ticks), "; the device stopped (its log is kept)");
  return rep;
}

}  // namespace palpate
