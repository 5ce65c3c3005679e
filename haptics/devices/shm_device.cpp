#include "haptics/devices/shm_device.h"

#include <algorithm>
#include <cmath>

#include "core/clock.h"
#include "haptics/force/force_limit.h"

namespace palpate {
namespace {

bool finite_in(double v, double lo, double hi) { return std::isfinite(v) && v > lo && v <= hi; }

}  // namespace

ShmDevice::ShmDevice(ShmSegment seg, const ShmParams& params, const DeviceSpecs& specs, const Rates& rates)
    : seg_(std::move(seg)),
      params_(params),
      rates_(rates),
      specs_(specs),
      watchdog_(static_cast<int64_t>(params.watchdog_s * 1e9)) {
  palpate_shim_segment* s = seg_.get();
  // continue the force counter of an earlier sim, so the device sees it move forward
  force_seq_ = __atomic_load_n(&s->force.force.seq, __ATOMIC_ACQUIRE);
  epoch_ = __atomic_load_n(&s->header.device_epoch, __ATOMIC_ACQUIRE);
  last_seq_ = __atomic_load_n(&s->pose.pose.seq, __ATOMIC_ACQUIRE);
}

ShmDevice::~ShmDevice() {
  // a live device keeps its name (it may serve the next session); a dead or stopped one leaves it to us
  const palpate_shim_segment* s = seg_.get();
  const bool stopped = __atomic_load_n(&s->header.device_state, __ATOMIC_ACQUIRE) == PALPATE_SHIM_DEVICE_STOPPED;
  if (stopped || !watchdog_.update(palpate_shim_beats(&s->device_hb), monotonic_ns())) ShmSegment::unlink(params_.name);
}

Result<std::unique_ptr<ShmDevice>> ShmDevice::connect(const ShmParams& p, const DeviceSpecs& limits, const Rates& rates) {
  const std::string what = "shm '" + p.name + "'";
  if (!(p.watchdog_s > 0.0 && p.watchdog_s <= 10.0)) return make_error(what, ": watchdog ", std::to_string(p.watchdog_s), " s out of range (0, 10]");
  if (!(p.max_speed_m_per_s > 0.0)) return make_error(what, ": max speed must be > 0");
  auto seg = ShmSegment::connect(p.name, p.connect_timeout_s);
  if (!seg) return seg.error();
  const palpate_shim_specs ds = seg.value().get()->specs;
  if (!finite_in(ds.max_force_N, 0.0, 1e3)) return make_error(what, ": device max_force_N ", std::to_string(ds.max_force_N), " out of range (0, 1000]");
  if (!finite_in(ds.workspace_half_m, 0.0, 100.0))
    return make_error(what, ": device workspace_half_m ", std::to_string(ds.workspace_half_m), " out of range (0, 100]");
  if (!finite_in(ds.max_stiffness_N_per_m, 0.0, 1e7))
    return make_error(what, ": device max_stiffness_N_per_m ", std::to_string(ds.max_stiffness_N_per_m), " out of range (0, 1e7]");
  if (!finite_in(ds.rate_hz, 0.0, 1e5)) return make_error(what, ": device rate_hz ", std::to_string(ds.rate_hz), " out of range (0, 1e5]");
  DeviceSpecs specs = limits;
  specs.max_force_N = std::min(limits.max_force_N, ds.max_force_N);
  specs.workspace_half_m = std::min(limits.workspace_half_m, ds.workspace_half_m);
  specs.max_stiffness_N_per_m = std::min(limits.max_stiffness_N_per_m, ds.max_stiffness_N_per_m);
  std::unique_ptr<ShmDevice> dev(new ShmDevice(std::move(seg).value(), p, specs, rates));

  // wait for a heartbeat, so a recording starts against a live device
  const int64_t deadline_ns = monotonic_ns() + static_cast<int64_t>(p.connect_timeout_s * 1e9);
  const uint64_t beats0 = palpate_shim_beats(&dev->seg_.get()->device_hb);
  dev->watchdog_.update(beats0, monotonic_ns());
  while (!dev->watchdog_.update(palpate_shim_beats(&dev->seg_.get()->device_hb), monotonic_ns())) {
    if (monotonic_ns() > deadline_ns)
      return make_error(what, ": the device's heartbeat did not move in ", std::to_string(p.connect_timeout_s),
                        " s (device process stopped or hung?)");
    sleep_until_ns(monotonic_ns() + 1'000'000);
  }
  return dev;
}

bool ShmDevice::accept(const palpate_shim_pose& p, int64_t now_ns) noexcept {
  const Vec3 pos(p.pos_m[0], p.pos_m[1], p.pos_m[2]);
  Quat q(p.quat_wxyz[0], p.quat_wxyz[1], p.quat_wxyz[2], p.quat_wxyz[3]);
  const double qn = q.norm();
  if (!pos.allFinite() || !std::isfinite(qn) || qn < 0.5 || qn > 2.0) {
    ++counters_.rejected_nonfinite;
    return false;
  }
  if (pos.cwiseAbs().maxCoeff() > specs_.workspace_half_m) {
    ++counters_.rejected_outside;
    return false;
  }
  if (have_good_) {
    // our own clock, not the peer's timestamps: those are untrusted too. The window is capped at a few periods,
    // so a servo that was late (a loaded machine) does not widen what counts as possible; a pose that stays away
    // for kReanchorRejects samples in a row is a real move made while we were not looking, and is taken
    const double period_s = rates_.servo_period_s();
    const double dt_s = std::clamp(static_cast<double>(now_ns - good_ns_) * 1e-9, period_s, 3.0 * period_s);
    if ((pos - good_.pos_m).norm() > params_.max_speed_m_per_s * dt_s && ++speed_rejects_in_row_ < kReanchorRejects) {
      ++counters_.rejected_speed;
      return false;
    }
  }
  speed_rejects_in_row_ = 0;
  good_.pos_m = pos;
  good_.orientation = Quat(q.coeffs() / qn);
  good_.buttons = static_cast<uint32_t>(p.buttons & 0xffffffffu);
  good_ns_ = now_ns;
  have_good_ = true;
  last_pose_time_ns_ = p.time_ns;
  ++counters_.poses;
  return true;
}

bool ShmDevice::read(double t_s, DevicePose* out) noexcept {
  palpate_shim_segment* s = seg_.get();
  const int64_t now = monotonic_ns();
  now_ns_ = now;
  palpate_shim_beat(&s->sim_hb, now);
  const int64_t tick = std::llround(t_s * rates_.servo_hz);

  // link health: the device's heartbeat, its state and its epoch (a new process attached)
  const bool stopped = __atomic_load_n(&s->header.device_state, __ATOMIC_ACQUIRE) == PALPATE_SHIM_DEVICE_STOPPED;
  const bool alive = watchdog_.update(palpate_shim_beats(&s->device_hb), now) && !stopped;
  const uint64_t epoch = __atomic_load_n(&s->header.device_epoch, __ATOMIC_ACQUIRE);
  if (epoch != epoch_) {
    epoch_ = epoch;
    have_good_ = false;  // a new device process may hold its handle elsewhere
    events_.push({tick, t_s, DeviceEventKind::kPeerRestarted, static_cast<double>(watchdog_.silent_ns(now)) * 1e-6});
  }
  if (alive != connected_) {
    const DeviceEventKind kind = alive ? (ever_connected_ ? DeviceEventKind::kReconnected : DeviceEventKind::kConnected)
                                       : DeviceEventKind::kDisconnected;
    events_.push({tick, t_s, kind, static_cast<double>(watchdog_.silent_ns(now)) * 1e-6});
    connected_ = alive;
    ever_connected_ = ever_connected_ || alive;
  }
  if (!connected_) {
    ++counters_.disconnected_ticks;
    new_pose_ns_ = 0;
    return false;
  }

  // a torn record is no reading: the last good pose is not fresh, and holding force on it would be felt
  palpate_shim_pose p{};
  if (!palpate_shim_read_pose(&s->pose, &p, 4)) {
    ++counters_.torn_reads;
    return false;
  }
  if (new_pose_ns_ == 0) new_pose_ns_ = now;  // the first look after (re)connecting starts the staleness clock
  if (p.seq != last_seq_) {
    last_seq_ = p.seq;
    new_pose_ns_ = now;
    if (!accept(p, now)) return false;
  } else if (now - new_pose_ns_ > watchdog_.timeout_ns()) {
    // a live heartbeat with a frozen pose: stale, counted as no reading until a new pose arrives
    ++counters_.stale_ticks;
    return false;
  }
  if (!have_good_) return false;
  *out = good_;
  return true;
}

void ShmDevice::write_force(const Vec3& force_N) noexcept {
  // zero at once while the link is down; the ramp back in is the servo's (it restarts after ticks without a
  // reading), so it shows in haptic.csv as what the device was sent
  const Vec3 f = limit_force(connected_ ? force_N : Vec3::Zero(), specs_.max_force_N);
  palpate_shim_force rec{};
  rec.seq = ++force_seq_;
  rec.time_ns = now_ns_;
  for (int i = 0; i < 3; ++i) rec.force_N[i] = f[i];
  rec.pose_seq = last_seq_;
  rec.pose_time_ns = last_pose_time_ns_;
  palpate_shim_write_force(&seg_.get()->force, &rec);
  sent_N_ = f;
  ++counters_.forces_sent;
}

nlohmann::json ShmDevice::report() const {
  nlohmann::json events = nlohmann::json::array();
  for (int i = 0; i < events_.count(); ++i) {
    const DeviceEvent& e = events_.at(i);
    events.push_back({{"tick", e.tick}, {"t_s", e.t_s}, {"event", device_event_name(e.kind)}, {"silent_ms", e.silent_ms}});
  }
  const ShmCounters& c = counters_;
  return {{"driver", "shm"},
          {"link", params_.name},
          {"connected_at_end", connected_},
          {"watchdog_ms", params_.watchdog_s * 1e3},
          {"events", events},
          {"events_lost", events_.lost()},
          {"poses", c.poses},
          {"rejected_nonfinite", c.rejected_nonfinite},
          {"rejected_outside", c.rejected_outside},
          {"rejected_speed", c.rejected_speed},
          {"torn_reads", c.torn_reads},
          {"stale_ticks", c.stale_ticks},
          {"disconnected_ticks", c.disconnected_ticks},
          {"forces_sent", c.forces_sent},
          {"segment_lost", seg_.lost()}};
}

}  // namespace palpate
