// The shim in one process: seqlock records stay consistent under a concurrent writer, the watchdog and ramp
// behave as specified, and the drivers' servo-thread calls never allocate.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <memory>

#include <atomic>
#include <cstdlib>
#include <string>
#include <thread>

#include "core/clock.h"
#include "haptics/devices/device_link.h"
#include "haptics/devices/plugin_device.h"
#include "haptics/devices/replay_device.h"
#include "haptics/devices/shm_device.h"
#include "haptics/devices/shm_segment.h"
#include "support/alloc_counter.h"

namespace palpate {
namespace {

const Rates kRates;  // the servo's (1 kHz): tick numbers of link events

std::string unique(const std::string& base) { return base + "-" + std::to_string(getpid()); }

palpate_shim_specs specs() {
  palpate_shim_specs s{};
  s.max_force_N = 3.3;
  s.max_stiffness_N_per_m = 700;
  s.workspace_half_m = 0.2;
  s.rate_hz = 1000;
  return s;
}

// A device side in a thread: beats and publishes a slowly moving pose until stopped.
struct FakeDevice {
  explicit FakeDevice(palpate_shim_segment* seg) : seg_(seg), thread_([this] { run(); }) {}
  ~FakeDevice() {
    stop = true;
    thread_.join();
  }
  void run() {
    uint64_t seq = seg_->pose.pose.seq;
    while (!stop) {
      if (!pause) {
        palpate_shim_pose p{};
        p.seq = ++seq;
        p.time_ns = monotonic_ns();
        p.pos_m[2] = 0.01 + 1e-7 * static_cast<double>(seq % 1000);
        p.quat_wxyz[0] = 1.0;
        palpate_shim_write_pose(&seg_->pose, &p);
        palpate_shim_beat(&seg_->device_hb, p.time_ns);
      }
      sleep_until_ns(monotonic_ns() + 200'000);
    }
  }
  std::atomic<bool> stop{false}, pause{false};
  palpate_shim_segment* seg_;
  std::thread thread_;
};

TEST(ShimSeqlock, ReaderNeverSeesAHalfWrittenPose) {
  const std::string name = unique("seqlock");
  auto seg = ShmSegment::serve(name, specs());
  ASSERT_TRUE(seg) << seg.error().message;
  ShmSegment::unlink(name);  // the mapping stays valid; nothing is left in /dev/shm whatever happens below
  palpate_shim_segment* s = seg.value().get();
  std::atomic<bool> stop{false};
  std::thread writer([&] {
    palpate_shim_pose p{};
    for (uint64_t i = 1; !stop; ++i) {
      // every field carries i, so a torn copy shows as a mismatch
      p.seq = i;
      p.time_ns = static_cast<int64_t>(i);
      for (double& v : p.pos_m) v = static_cast<double>(i);
      for (double& v : p.quat_wxyz) v = static_cast<double>(i);
      p.buttons = i;
      palpate_shim_write_pose(&s->pose, &p);
      if (i % 8 == 0) std::this_thread::yield();  // hot, but leaves the reader gaps to succeed in
    }
  });
  // count torn copies instead of asserting here: a failure must not abort the binary with the writer running
  int64_t good = 0, torn = 0;
  const int64_t end_ns = monotonic_ns() + 3'000'000'000LL;
  while (good < 20000 && monotonic_ns() < end_ns) {
    palpate_shim_pose p{};
    if (!palpate_shim_read_pose(&s->pose, &p, 8) || p.seq == 0) continue;
    ++good;
    const auto i = static_cast<double>(p.seq);
    bool same = static_cast<double>(p.time_ns) == i && p.buttons == p.seq;
    for (double v : p.pos_m) same = same && v == i;
    for (double v : p.quat_wxyz) same = same && v == i;
    if (!same) ++torn;
  }
  stop = true;
  writer.join();
  EXPECT_GT(good, 0);
  EXPECT_EQ(torn, 0) << "of " << good << " reads";
}

TEST(ShimSegment, ServeIsOwnerOnlyAndReattachBumpsTheEpoch) {
  const std::string name = unique("epoch");
  auto a = ShmSegment::serve(name, specs());
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_EQ(a.value().get()->header.device_epoch, 1u);
  auto b = ShmSegment::serve(name, specs());
  ASSERT_TRUE(b);
  EXPECT_EQ(b.value().get()->header.device_epoch, 2u);
  EXPECT_EQ(a.value().get()->header.device_epoch, 2u);  // the same memory
  struct stat st {};
  ASSERT_EQ(stat(("/dev/shm" + ShmSegment::path_of(name)).c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777u, 0600u);
  ShmSegment::unlink(name);
}

TEST(DeviceLink, WatchdogNeedsAMovingCounterAndTimesOut) {
  PeerWatchdog w(5'000'000);
  EXPECT_FALSE(w.update(7, 0));            // a baseline only: a dead peer's counter never looks alive
  EXPECT_FALSE(w.update(7, 1'000'000));
  EXPECT_TRUE(w.update(8, 2'000'000));
  EXPECT_TRUE(w.update(8, 7'000'000));
  EXPECT_FALSE(w.update(8, 7'000'001));
  EXPECT_TRUE(w.update(9, 8'000'000));
}

TEST(DeviceLink, RampIsLinearAndResetIsImmediate) {
  ForceRamp r(100'000'000);
  r.reset(0.0, 0);
  EXPECT_NEAR(r.update(1.0, 50'000'000), 0.5, 1e-12);
  EXPECT_NEAR(r.update(1.0, 200'000'000), 1.0, 1e-12);
  r.reset(0.0, 200'000'000);
  EXPECT_EQ(r.gain(), 0.0);
  EXPECT_NEAR(r.update(1.0, 210'000'000), 0.1, 1e-12);
}

TEST(ShmDevice, DisconnectsWhenTheDeviceStopsAndReconnectsWhenItResumes) {
  const std::string name = unique("wd");
  auto seg = ShmSegment::serve(name, specs());
  ASSERT_TRUE(seg);
  FakeDevice dev(seg.value().get());
  ShmParams p;
  p.name = name;
  p.watchdog_s = 0.05;
  auto d = ShmDevice::connect(p, DeviceSpecs{}, kRates);
  ASSERT_TRUE(d) << d.error().message;
  ShmDevice& shm = *d.value();
  DevicePose pose;
  int64_t tick = 0;
  auto run_for = [&](double s) {
    const int64_t end = monotonic_ns() + static_cast<int64_t>(s * 1e9);
    while (monotonic_ns() < end) {
      shm.read(static_cast<double>(tick++) * 1e-3, &pose);
      shm.write_force(Vec3(0, 0, 1));
      sleep_until_ns(monotonic_ns() + 1'000'000);
    }
  };
  run_for(0.05);
  EXPECT_TRUE(shm.connected());
  dev.pause = true;
  run_for(0.3);
  EXPECT_FALSE(shm.connected());
  EXPECT_EQ(shm.last_force_sent_N().norm(), 0.0);
  EXPECT_FALSE(shm.read(static_cast<double>(tick) * 1e-3, &pose));
  dev.pause = false;
  run_for(0.1);
  EXPECT_TRUE(shm.connected());
  EXPECT_EQ(shm.last_force_sent_N().z(), 1.0);
  ASSERT_GE(shm.events().count(), 3);
  EXPECT_EQ(shm.events().at(0).kind, DeviceEventKind::kConnected);
  EXPECT_EQ(shm.events().at(1).kind, DeviceEventKind::kDisconnected);
  EXPECT_GE(shm.events().at(1).silent_ms, 50.0);
  EXPECT_EQ(shm.events().at(2).kind, DeviceEventKind::kReconnected);
  EXPECT_GT(shm.events().at(2).tick, shm.events().at(1).tick);
  ShmSegment::unlink(name);
}

// A device side whose heartbeat lives while its pose record is stuck: torn (lock left odd) or frozen (no new seq).
struct HeartbeatOnly {
  explicit HeartbeatOnly(palpate_shim_segment* seg) : seg_(seg), thread_([this] {
    while (!stop) {
      palpate_shim_beat(&seg_->device_hb, monotonic_ns());
      sleep_until_ns(monotonic_ns() + 200'000);
    }
  }) {}
  ~HeartbeatOnly() {
    stop = true;
    thread_.join();
  }
  palpate_shim_segment* seg_;
  std::atomic<bool> stop{false};
  std::thread thread_;
};

// Reads for `s` seconds at about 1 kHz; returns how many reads gave a pose.
int read_for(ShmDevice* shm, double s, int64_t* tick) {
  int got = 0;
  DevicePose pose;
  const int64_t end = monotonic_ns() + static_cast<int64_t>(s * 1e9);
  while (monotonic_ns() < end) {
    got += shm->read(static_cast<double>((*tick)++) * 1e-3, &pose) ? 1 : 0;
    shm->write_force(Vec3(0, 0, 1));
    sleep_until_ns(monotonic_ns() + 1'000'000);
  }
  return got;
}

// Another process of the same user truncates the segment mid-run: both sides' next access would raise SIGBUS
// and kill the process (the recording with its summary). Both survive: the lost pages read as zeros, the
// segment says it is lost, the sim side sees a silent device and sends no force.
TEST(ShmSegment, TruncatedUnderTheMappingIsLostNotFatal) {
  const std::string name = unique("trunc");
  auto seg = ShmSegment::serve(name, specs());
  ASSERT_TRUE(seg);
  FakeDevice dev(seg.value().get());
  ShmParams p;
  p.name = name;
  p.watchdog_s = 0.02;
  auto d = ShmDevice::connect(p, DeviceSpecs{}, kRates);
  ASSERT_TRUE(d) << d.error().message;
  ShmDevice& shm = *d.value();
  int64_t tick = 0;
  EXPECT_GT(read_for(&shm, 0.05, &tick), 0);
  EXPECT_FALSE(seg.value().lost());
  const int fd = shm_open(ShmSegment::path_of(name).c_str(), O_RDWR, 0);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(ftruncate(fd, 0), 0);
  close(fd);
  EXPECT_EQ(read_for(&shm, 0.2, &tick), 0);
  EXPECT_FALSE(shm.connected());
  EXPECT_EQ(shm.last_force_sent_N().norm(), 0.0);
  EXPECT_TRUE(shm.report()["segment_lost"].get<bool>());
  // the device side faulted too (its thread writes every 0.2 ms) and was kept alive the same way
  for (int i = 0; i < 500 && !seg.value().lost(); ++i) sleep_until_ns(monotonic_ns() + 1'000'000);
  EXPECT_TRUE(seg.value().lost());
  ShmSegment::unlink(name);
}

TEST(ShmDevice, TornPoseIsAMissingReadingNotTheLastGoodPose) {
  const std::string name = unique("torn");
  auto seg = ShmSegment::serve(name, specs());
  ASSERT_TRUE(seg);
  palpate_shim_segment* sg = seg.value().get();
  ShmParams p;
  p.name = name;
  p.watchdog_s = 0.05;
  std::unique_ptr<ShmDevice> shm;
  int64_t tick = 0;
  {
    FakeDevice dev(sg);
    auto d = ShmDevice::connect(p, DeviceSpecs{}, kRates);
    ShmSegment::unlink(name);  // the mappings stay valid; nothing is left in /dev/shm whatever happens below
    ASSERT_TRUE(d) << d.error().message;
    shm = std::move(d).value();
    EXPECT_GT(read_for(shm.get(), 0.03, &tick), 0);
  }
  HeartbeatOnly hb(sg);
  // a pose write that never finished: the lock stays odd, every later read is torn
  __atomic_store_n(&sg->pose.lock, __atomic_load_n(&sg->pose.lock, __ATOMIC_RELAXED) | 1u, __ATOMIC_RELEASE);
  EXPECT_EQ(read_for(shm.get(), 0.05, &tick), 0);
  EXPECT_TRUE(shm->connected());
  EXPECT_GT(shm->counters().torn_reads, 0);
  ShmSegment::unlink(name);
}

TEST(ShmDevice, FrozenPoseIsStaleAfterTheWatchdog) {
  const std::string name = unique("stale");
  auto seg = ShmSegment::serve(name, specs());
  ASSERT_TRUE(seg);
  palpate_shim_segment* sg = seg.value().get();
  ShmParams p;
  p.name = name;
  p.watchdog_s = 0.02;
  std::unique_ptr<ShmDevice> shm;
  int64_t tick = 0;
  {
    FakeDevice dev(sg);
    auto d = ShmDevice::connect(p, DeviceSpecs{}, kRates);
    ShmSegment::unlink(name);  // the mappings stay valid; nothing is left in /dev/shm whatever happens below
    ASSERT_TRUE(d) << d.error().message;
    shm = std::move(d).value();
    EXPECT_GT(read_for(shm.get(), 0.03, &tick), 0);
  }
  HeartbeatOnly hb(sg);  // alive, but no new pose
  read_for(shm.get(), 0.03, &tick);
  EXPECT_EQ(read_for(shm.get(), 0.05, &tick), 0);
  EXPECT_GT(shm->counters().stale_ticks, 0);
  ShmSegment::unlink(name);
}

TEST(ShimSeqlock, WriterMendsALockLeftOdd) {
  palpate_shim_pose_slot slot{};
  slot.lock = 7;  // a write that died half way
  palpate_shim_pose in{};
  in.seq = 42;
  in.quat_wxyz[0] = 1.0;
  palpate_shim_write_pose(&slot, &in);
  palpate_shim_pose out{};
  ASSERT_EQ(palpate_shim_read_pose(&slot, &out, 1), 1);
  EXPECT_EQ(out.seq, 42u);
  EXPECT_EQ(slot.lock % 2, 0u);
}

TEST(ShimSegment, SecondServerIsRefusedWhileTheFirstLives) {
  const std::string name = unique("twice");
  auto a = ShmSegment::serve(name, specs());
  ASSERT_TRUE(a);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    pause();
    _exit(0);
  }
  // the segment as a device process `child` serves it
  a.value().get()->header.device_pid = static_cast<uint64_t>(child);
  auto b = ShmSegment::serve(name, specs());
  kill(child, SIGKILL);  // before any assertion: a failed one must not leave the child behind
  waitpid(child, nullptr, 0);
  auto c = ShmSegment::serve(name, specs());  // its process gone: the name is free again
  ShmSegment::unlink(name);
  ASSERT_FALSE(b.ok());
  EXPECT_NE(b.error().message.find("already served by device process " + std::to_string(child)), std::string::npos)
      << b.error().message;
  EXPECT_TRUE(c.ok()) << c.error().message;
}

TEST(ShmDevice, TenThousandTicksAllocateNothing) {
  const std::string name = unique("alloc");
  auto seg = ShmSegment::serve(name, specs());
  ASSERT_TRUE(seg);
  FakeDevice dev(seg.value().get());
  ShmParams p;
  p.name = name;
  auto d = ShmDevice::connect(p, DeviceSpecs{}, kRates);
  ASSERT_TRUE(d) << d.error().message;
  DevicePose pose;
  test::AllocationGuard guard;
  for (int i = 0; i < 10000; ++i) {
    d.value()->read(i * 1e-3, &pose);
    d.value()->write_force(Vec3(0.1, 0, 0));
  }
  EXPECT_EQ(guard.count(), 0);
  ShmSegment::unlink(name);
}

TEST(ReplayDevice, TenThousandTicksAllocateNothing) {
  std::vector<ReplayRow> rows;
  for (int i = 0; i < 2000; ++i) rows.push_back({i * 1e-3, Vec3(0, 0, 0.01 * i / 2000.0), 0, i % 500 == 7});
  ReplayDevice d(DeviceSpecs{}, rows);
  DevicePose pose;
  test::AllocationGuard guard;
  int rejected = 0;
  for (int i = 0; i < 10000; ++i) {
    rejected += d.read(i * 1e-3, &pose) ? 0 : 1;
    d.write_force(Vec3(0.1, 0, 0));
  }
  EXPECT_EQ(guard.count(), 0);
  EXPECT_EQ(rejected, 4);  // the recording's rejected rows are rejected again
}

TEST(PluginDevice, TenThousandTicksThroughTheEmulatedPluginAllocateNothing) {
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  const std::string path = std::string(bin ? bin : "build/bin") + "/../lib/libpalpate_emulated_plugin.so";
  auto d = PluginDevice::load(path, "hand=0.12,150,6;key=0,0,0,0.05,0;key=1,0,0,0.01,1", DeviceSpecs{});
  ASSERT_TRUE(d) << d.error().message;
  DevicePose pose;
  test::AllocationGuard guard;
  for (int i = 0; i < 10000; ++i) {
    ASSERT_TRUE(d.value()->read(i * 1e-3, &pose));
    d.value()->write_force(Vec3(0.1, 0, 0));
  }
  EXPECT_EQ(guard.count(), 0);
  EXPECT_NEAR(pose.pos_m.z(), 0.01, 2e-3);  // followed the keyframes
  EXPECT_EQ(pose.buttons, 1u);
}

TEST(PluginDevice, OpenErrorsCarryThePluginsMessage) {
  const char* bin = std::getenv("PALPATE_BIN_DIR");
  const std::string path = std::string(bin ? bin : "build/bin") + "/../lib/libpalpate_emulated_plugin.so";
  auto d = PluginDevice::load(path, "hand=0.12,150,6", DeviceSpecs{});
  ASSERT_FALSE(d);
  EXPECT_NE(d.error().message.find("open failed: emulated: no trajectory"), std::string::npos) << d.error().message;
}

}  // namespace
}  // namespace palpate
