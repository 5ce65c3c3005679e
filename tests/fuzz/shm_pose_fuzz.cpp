// libFuzzer target: the bytes a device process writes into the shared segment -> ShmDevice::read(). The input
// is laid over the pose slot (seqlock word, sequence, timestamp, position, orientation, buttons) and the
// header's device state and epoch, one record per 96 bytes; each record is followed by a read on the servo's
// clock. Whatever the peer writes, a reading the driver gives is finite, inside the workspace, with a unit
// quaternion; and the force it sends back stays within its limit.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>

#include "core/clock.h"
#include "haptics/devices/shm_device.h"
#include "haptics/devices/shm_segment.h"

namespace {

constexpr double kWorkspace_m = 0.5;
constexpr double kMaxForce_N = 3.0;

// A segment served by this process and a driver connected to it, made once (connect() waits for a heartbeat,
// which a thread gives until it returns).
struct Link {
  palpate::ShmSegment served;
  palpate::Rates rates;  // the servo's (1 kHz)
  std::unique_ptr<palpate::ShmDevice> device;
  std::string name = "fuzz-" + std::to_string(::getpid());

  Link() {
    palpate_shim_specs specs{};
    specs.max_force_N = kMaxForce_N;
    specs.max_stiffness_N_per_m = 1000.0;
    specs.workspace_half_m = kWorkspace_m;
    specs.rate_hz = 1000.0;
    auto seg = palpate::ShmSegment::serve(name, specs);
    if (!seg) std::abort();
    served = std::move(seg).value();
    std::atomic<bool> connected{false};
    std::thread beat([&] {
      while (!connected.load()) {
        palpate_shim_beat(&served.get()->device_hb, palpate::monotonic_ns());
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
    });
    palpate::ShmParams p;
    p.name = name;
    p.watchdog_s = 10.0;  // the fuzzer's pace is not a device's: only what is written is under test
    p.connect_timeout_s = 5.0;
    palpate::DeviceSpecs limits;
    limits.workspace_half_m = kWorkspace_m;
    limits.max_force_N = kMaxForce_N;
    auto dev = palpate::ShmDevice::connect(p, limits, rates);
    connected = true;
    beat.join();
    if (!dev) std::abort();
    device = std::move(dev).value();
  }
  ~Link() {
    device.reset();
    palpate::ShmSegment::unlink(name);
  }
};

template <class T>
T take(const uint8_t*& p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  p += sizeof v;
  return v;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  static Link link;
  static double t_s = 0.0;
  palpate_shim_segment* seg = link.served.get();
  constexpr std::size_t kRecord = 8 + 80 + 8;  // lock, pose, state/epoch byte pair
  for (std::size_t off = 0; off + kRecord <= size; off += kRecord) {
    const uint8_t* p = data + off;
    const auto lock = take<uint64_t>(p);
    palpate_shim_pose pose;
    std::memcpy(&pose, p, sizeof pose);
    p += sizeof pose;
    const auto state = take<uint32_t>(p);
    const auto epoch = take<uint32_t>(p);
    __atomic_store_n(&seg->pose.lock, lock, __ATOMIC_RELAXED);
    PALPATE_SHIM_ST(seg->pose.pose.seq, pose.seq);
    PALPATE_SHIM_ST(seg->pose.pose.time_ns, pose.time_ns);
    for (int i = 0; i < 3; ++i) PALPATE_SHIM_ST(seg->pose.pose.pos_m[i], pose.pos_m[i]);
    for (int i = 0; i < 4; ++i) PALPATE_SHIM_ST(seg->pose.pose.quat_wxyz[i], pose.quat_wxyz[i]);
    PALPATE_SHIM_ST(seg->pose.pose.buttons, pose.buttons);
    // mostly running, sometimes stopped or an unknown state; the epoch moves now and then (a restart)
    const uint64_t st = state % 8 == 0 ? uint64_t{state} : uint64_t{PALPATE_SHIM_DEVICE_RUNNING};
    __atomic_store_n(&seg->header.device_state, st, __ATOMIC_RELEASE);
    if (epoch % 16 == 0) __atomic_store_n(&seg->header.device_epoch, seg->header.device_epoch + 1, __ATOMIC_RELEASE);
    palpate_shim_beat(&seg->device_hb, palpate::monotonic_ns());

    t_s += 0.001;
    palpate::DevicePose out;
    if (link.device->read(t_s, &out)) {
      if (!out.pos_m.allFinite() || out.pos_m.cwiseAbs().maxCoeff() > kWorkspace_m) std::abort();
      if (!out.orientation.coeffs().allFinite() || std::abs(out.orientation.norm() - 1.0) > 1e-9) std::abort();
    }
    // a force from the pose, as the servo would send; the driver clamps it
    link.device->write_force(palpate::Vec3(pose.pos_m[0], pose.pos_m[1], pose.pos_m[2]) * 1e3);
    palpate_shim_force f{};
    if (palpate_shim_read_force(&seg->force, &f, 4)) {
      const double n = std::sqrt(f.force_N[0] * f.force_N[0] + f.force_N[1] * f.force_N[1] + f.force_N[2] * f.force_N[2]);
      if (!(n <= kMaxForce_N * (1 + 1e-12))) std::abort();
    }
  }
  // state back to running for the next input
  __atomic_store_n(&seg->header.device_state, uint64_t{PALPATE_SHIM_DEVICE_RUNNING}, __ATOMIC_RELEASE);
  __atomic_store_n(&seg->pose.lock, seg->pose.lock & ~uint64_t{1}, __ATOMIC_RELAXED);
  return 0;
}
