// Device in the loop across a real process boundary: palpate-device serves the shim, palpate record runs the
// scene against it, and faults are injected from outside (SIGSTOP, SIGKILL, restart, killing the sim).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "core/clock.h"
#include "haptics/devices/shm_segment.h"
#include "render/png_io.h"
#include "tools/device/device_process.h"

namespace palpate {
namespace {
namespace fs = std::filesystem;
using test::Child;
using test::Csv;

constexpr double kWait_s = 30.0;  // generous bounds: the machine is shared and loaded

std::string fresh(const std::string& name) {
  const fs::path p = fs::path(test::temp_root()) / ("palpate_dev_" + name);
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

Child start_device(const std::string& link, const std::string& scene, const std::string& dir, const std::string& tag,
                   const std::vector<std::string>& extra = {}) {
  std::vector<std::string> a = {test::bin_dir() + "/palpate-device", "--name", link, "--scene", scene,
                                "--log", dir + "/device_" + tag + ".csv"};
  a.insert(a.end(), extra.begin(), extra.end());
  return Child(a, dir + "/device_" + tag + ".out");
}

Child start_record(const std::string& link, const std::string& scene, const std::string& dir, bool render) {
  std::vector<std::string> a = {test::bin_dir() + "/palpate", "record", scene, "--device", "shm:" + link,
                                "--out", dir + "/rec"};
  if (!render) a.push_back("--no-render");
  return Child(a, dir + "/record.out");
}

nlohmann::json summary(const std::string& dir) {
  return nlohmann::json::parse(test::read_file(dir + "/rec/summary.json"));
}

// Every output of a finished recording is there and whole.
void expect_complete(const std::string& dir, const nlohmann::json& s, int frames) {
  const Csv h = test::read_csv(dir + "/rec/haptic.csv");
  EXPECT_EQ(static_cast<int64_t>(h.rows.size()), s["servo_ticks"].get<int64_t>());
  EXPECT_EQ(static_cast<int64_t>(h.rows.size()), s["haptic_rows"].get<int64_t>());
  EXPECT_FALSE(fs::exists(dir + "/rec/haptic.csv.partial"));
  EXPECT_TRUE(fs::exists(dir + "/rec/device_events.csv"));
  int pngs = 0;
  // (a run without rendering makes no frames/ folder)
  EXPECT_EQ(fs::exists(dir + "/rec/frames"), s["outputs"]["frames"].is_string()) << s["outputs"].dump();
  if (fs::exists(dir + "/rec/frames"))
  for (const auto& e : fs::directory_iterator(dir + "/rec/frames")) {
    ASSERT_EQ(e.path().extension(), ".png") << e.path();  // no temporary left behind
    EXPECT_TRUE(read_png(e.path().string())) << e.path();
    ++pngs;
  }
  // realtime: frames the pipeline could not keep up with are skipped, never half written
  EXPECT_EQ(pngs, s["frames_written"].get<int>());
  EXPECT_LE(pngs, frames);
  EXPECT_GE(pngs, frames / 2);
}

// Events of one kind in the summary, in order.
std::vector<int64_t> ticks_of(const nlohmann::json& s, const std::string& kind) {
  std::vector<int64_t> t;
  for (const auto& e : s["device"]["events"])
    if (e["event"] == kind) t.push_back(e["tick"].get<int64_t>());
  return t;
}

TEST(DeviceLink, GarbageInTheForceSlotIsRefusedNotRendered) {
  // a sim side writing forces far past the device's maximum: the device must not render them clamped to full force
  const std::string dir = fresh("garbage");
  const std::string link = test::link_name("garbage");
  const std::string scene = test::device_scene(link, 1.0, {});
  Child dev = start_device(link, scene, dir, "g", {"--duration", "1.0", "--priority", "0", "-q"});
  auto seg = ShmSegment::connect(link, kWait_s);
  ASSERT_TRUE(seg) << seg.error().message;
  palpate_shim_segment* s = seg.value().get();
  uint64_t seq = __atomic_load_n(&s->force.force.seq, __ATOMIC_ACQUIRE);
  const int64_t end_ns = monotonic_ns() + 400'000'000;
  while (monotonic_ns() < end_ns) {
    const int64_t now = monotonic_ns();
    palpate_shim_beat(&s->sim_hb, now);
    palpate_shim_force f{};
    f.seq = ++seq;
    f.time_ns = now;
    f.force_N[0] = 1e6;
    f.force_N[1] = -3e5;
    f.force_N[2] = 7e4;
    palpate_shim_write_force(&s->force, &f);
    sleep_until_ns(monotonic_ns() + 1'000'000);
  }
  ASSERT_EQ(dev.wait(kWait_s), 0) << dev.output();
  const Csv log = test::read_csv(dir + "/device_g.csv");
  const int fx = log.col("force_x_N"), fy = log.col("force_y_N"), fz = log.col("force_z_N");
  ASSERT_GE(fx, 0);
  double max_N = 0.0;
  for (const auto& r : log.rows) max_N = std::max(max_N, std::hypot(r[fx], r[fy], r[fz]));
  EXPECT_EQ(max_N, 0.0) << "garbage commands were rendered";
  ShmSegment::unlink(link);
}

TEST(DeviceLink, RecordsAgainstTheDeviceProcessAndBothEndCleanly) {
  const std::string dir = fresh("e2e"), link = test::link_name("e2e");
  const std::string scene = test::device_scene("dev_e2e", 1.5, {{"watchdog_ms", 50}});
  Child dev = start_device(link, scene, dir, "a");
  ASSERT_TRUE(dev.wait_for_output("serving shm", kWait_s)) << dev.output();
  Child rec = start_record(link, scene, dir, true);
  ASSERT_EQ(rec.wait(kWait_s * 2), 0) << rec.output();
  dev.signal(SIGTERM);
  ASSERT_EQ(dev.wait(kWait_s), 0) << dev.output();

  const auto s = summary(dir);
  EXPECT_EQ(s["mode"], "realtime");
  EXPECT_EQ(s["device"]["driver"], "shm");
  ASSERT_GE(s["device"]["events"].size(), 1u);
  EXPECT_EQ(s["device"]["events"][0]["event"], "connected");
  EXPECT_GT(s["device"]["poses"].get<int64_t>(), 500);
  EXPECT_GT(s["max_force_N"].get<double>(), 0.1);  // the press reached the cube through the link
  expect_complete(dir, s, 90);

  // the device felt it, reported its timing, and removed the segment
  const Csv d = test::read_csv(dir + "/device_a.csv");
  double max_applied = 0.0;
  for (const auto& r : d.rows) max_applied = std::max(max_applied, std::hypot(r[9], r[10], r[11]));
  EXPECT_GT(max_applied, 0.1);
  EXPECT_NE(dev.output().find("wake latency"), std::string::npos);
  EXPECT_NE(dev.output().find("round trip"), std::string::npos);
  EXPECT_FALSE(fs::exists("/dev/shm/palpate-" + link));
}

TEST(DeviceLink, SilentDeviceZeroesForceAtOnceAndRampsBackIn) {
  const std::string dir = fresh("stall"), link = test::link_name("stall");
  const std::string scene = test::device_scene("dev_stall", 2.5, {{"watchdog_ms", 30}, {"ramp_s", 0.3}});
  Child dev = start_device(link, scene, dir, "a");
  ASSERT_TRUE(dev.wait_for_output("serving shm", kWait_s));
  Child rec = start_record(link, scene, dir, false);
  ASSERT_TRUE(dev.wait_for_output("sim connected", kWait_s)) << dev.output();
  test::sleep_s(0.5);  // pressing by now
  dev.signal(SIGSTOP);
  test::sleep_s(0.4);
  dev.signal(SIGCONT);
  ASSERT_EQ(rec.wait(kWait_s * 2), 0) << rec.output();
  dev.signal(SIGTERM);
  ASSERT_EQ(dev.wait(kWait_s), 0) << dev.output();

  const auto s = summary(dir);
  const auto down = ticks_of(s, "disconnected"), up = ticks_of(s, "reconnected");
  ASSERT_GE(down.size(), 1u) << s["device"].dump();
  ASSERT_GE(up.size(), 1u) << s["device"].dump();
  EXPECT_GT(up.back(), down.front());
  EXPECT_NE(rec.output().find("disconnected at tick " + std::to_string(down.front())), std::string::npos) << rec.output();
  EXPECT_NE(test::read_file(dir + "/rec/device_events.csv").find(std::to_string(down.front()) + ","), std::string::npos);

  // force is zero from the disconnect tick until the reconnect, and the ticks are flagged
  const Csv h = test::read_csv(dir + "/rec/haptic.csv");
  const int tick = h.col("tick"), fx = h.col("force_x_N"), rej = h.col("rejected");
  int64_t silent_rows = 0;
  for (const auto& r : h.rows) {
    const auto t = static_cast<int64_t>(r[static_cast<std::size_t>(tick)]);
    if (t < down.front() || t >= up.front()) continue;
    ++silent_rows;
    EXPECT_EQ(std::hypot(r[static_cast<std::size_t>(fx)], r[static_cast<std::size_t>(fx) + 1], r[static_cast<std::size_t>(fx) + 2]), 0.0) << "tick " << t;
    EXPECT_EQ(r[static_cast<std::size_t>(rej)], 1.0) << "tick " << t;
  }
  EXPECT_GT(silent_rows, 100);  // about the 400 ms stop, less the watchdog

  // the device saw the force come back as a ramp: no step from zero to full force
  const Csv d = test::read_csv(dir + "/device_a.csv");
  // the device's own log has a gap where it was stopped; the first force it received after it is small
  auto cmd = [&](std::size_t i) { return std::hypot(d.rows[i][6], d.rows[i][7], d.rows[i][8]); };
  std::size_t resume = 0, first = 0;
  for (std::size_t i = 1; i < d.rows.size() && !resume; ++i)
    if (d.rows[i][1] - d.rows[i - 1][1] > 0.2) resume = i;
  ASSERT_GT(resume, 0u) << "no stop found in the device log";
  for (std::size_t i = resume; i < d.rows.size() && !first; ++i)
    if (cmd(i) > 0.0) first = i;
  // (the servo may keep the coupling off after the jump the stopped hand makes on resume: then there is no
  // return to look at, and the zero-force checks above carry the test)
  if (first > 0) {
    double later = 0.0;
    for (std::size_t i = first; i < std::min(d.rows.size(), first + 400); ++i) later = std::max(later, cmd(i));
    EXPECT_LT(cmd(first), 0.25 * later);
  }
  expect_complete(dir, s, 0);
}

TEST(DeviceLink, DeviceKilledAndRestartedMidRun) {
  const std::string dir = fresh("restart"), link = test::link_name("restart");
  const std::string scene = test::device_scene("dev_restart", 2.5, {{"watchdog_ms", 30}});
  Child dev = start_device(link, scene, dir, "a");
  ASSERT_TRUE(dev.wait_for_output("serving shm", kWait_s));
  Child rec = start_record(link, scene, dir, false);
  ASSERT_TRUE(dev.wait_for_output("sim connected", kWait_s)) << dev.output();
  test::sleep_s(0.4);
  dev.signal(SIGKILL);
  EXPECT_EQ(dev.wait(kWait_s), -SIGKILL);
  test::sleep_s(0.3);
  Child dev2 = start_device(link, scene, dir, "b");
  ASSERT_EQ(rec.wait(kWait_s * 2), 0) << rec.output();
  ASSERT_TRUE(dev2.wait_for_output("sim connected", kWait_s)) << dev2.output();
  dev2.signal(SIGTERM);
  ASSERT_EQ(dev2.wait(kWait_s), 0) << dev2.output();

  const auto s = summary(dir);
  const auto down = ticks_of(s, "disconnected"), restarted = ticks_of(s, "peer_restarted"), up = ticks_of(s, "reconnected");
  ASSERT_GE(down.size(), 1u) << s["device"].dump();
  ASSERT_GE(restarted.size(), 1u) << s["device"].dump();
  ASSERT_GE(up.size(), 1u) << s["device"].dump();
  EXPECT_GT(up.back(), down.front());
  EXPECT_FALSE(s["device"]["connected_at_end"].get<bool>() && up.back() < down.back());
  // the restarted device served the rest of the run: its hand pressed the cube again and the coupling came back,
  // so force reached it (its log has a row every tick whether or not any force arrives: count force, not rows)
  const Csv d2 = test::read_csv(dir + "/device_b.csv");
  double b_max_N = 0.0;
  int64_t b_forced = 0;
  for (const auto& r : d2.rows) {
    const double f = std::hypot(r[9], r[10], r[11]);
    if (r[13] == 1.0) b_max_N = std::max(b_max_N, f);
    if (f > 0.05) ++b_forced;
  }
  EXPECT_GT(b_max_N, 0.1) << "no force reached the restarted device";
  EXPECT_GT(b_forced, 100);
  // the sim's own log agrees: after the reconnect, accepted readings with force on them
  const Csv h = test::read_csv(dir + "/rec/haptic.csv");
  const int tick = h.col("tick"), fx = h.col("force_x_N"), rej = h.col("rejected");
  int64_t forced_after = 0;
  for (const auto& r : h.rows) {
    const auto at = [&](int c) { return r[static_cast<std::size_t>(c)]; };
    if (static_cast<int64_t>(at(tick)) <= up.back() || at(rej) != 0.0) continue;
    if (std::hypot(at(fx), at(fx + 1), at(fx + 2)) > 0.05) ++forced_after;
  }
  EXPECT_GT(forced_after, 100) << "force did not come back after the reconnect";
  expect_complete(dir, s, 0);
}

TEST(DeviceLink, DeviceCrashLeavesAWholeRecordingWithZeroForce) {
  const std::string dir = fresh("crash"), link = test::link_name("crash");
  const std::string scene = test::device_scene("dev_crash", 1.5, {{"watchdog_ms", 30}});
  Child dev = start_device(link, scene, dir, "a");
  ASSERT_TRUE(dev.wait_for_output("serving shm", kWait_s));
  Child rec = start_record(link, scene, dir, true);
  ASSERT_TRUE(dev.wait_for_output("sim connected", kWait_s)) << dev.output();
  test::sleep_s(0.5);
  dev.signal(SIGSEGV);
  EXPECT_EQ(dev.wait(kWait_s), -SIGSEGV);
  ASSERT_EQ(rec.wait(kWait_s * 2), 0) << rec.output();

  const auto s = summary(dir);
  const auto down = ticks_of(s, "disconnected");
  ASSERT_EQ(down.size(), 1u) << s["device"].dump();
  EXPECT_FALSE(s["device"]["connected_at_end"].get<bool>());
  const Csv h = test::read_csv(dir + "/rec/haptic.csv");
  const int tick = h.col("tick"), fx = h.col("force_x_N");
  for (const auto& r : h.rows) {
    if (r[static_cast<std::size_t>(tick)] < static_cast<double>(down[0])) continue;
    ASSERT_EQ(std::hypot(r[static_cast<std::size_t>(fx)], r[static_cast<std::size_t>(fx) + 1], r[static_cast<std::size_t>(fx) + 2]), 0.0);
  }
  expect_complete(dir, s, 90);
  ShmSegment::unlink(link);  // normally already removed by the sim when it closed the dead link
}

TEST(DeviceLink, SimKilledDeviceRampsItsForceToZero) {
  const std::string dir = fresh("simkill"), link = test::link_name("simkill");
  const std::string scene = test::device_scene("dev_simkill", 5.0, {{"watchdog_ms", 50}});
  Child dev = start_device(link, scene, dir, "a", {"--sim-watchdog-ms", "20", "--release-ms", "100"});
  ASSERT_TRUE(dev.wait_for_output("serving shm", kWait_s));
  Child rec = start_record(link, scene, dir, true);
  ASSERT_TRUE(dev.wait_for_output("sim connected", kWait_s)) << dev.output();
  test::sleep_s(0.8);  // pressing into the cube
  rec.signal(SIGKILL);
  EXPECT_EQ(rec.wait(kWait_s), -SIGKILL);
  ASSERT_TRUE(dev.wait_for_output("sim silent", kWait_s)) << dev.output();
  test::sleep_s(0.3);
  dev.signal(SIGTERM);
  ASSERT_EQ(dev.wait(kWait_s), 0) << dev.output();

  // device log: force applied while the sim lived, then a monotone ramp to exactly zero
  const Csv d = test::read_csv(dir + "/device_a.csv");
  std::size_t last_alive = 0;
  double before = 0.0;
  for (std::size_t i = 0; i < d.rows.size(); ++i)
    if (d.rows[i][13] == 1.0) {
      last_alive = i;
      before = std::max(before, std::hypot(d.rows[i][9], d.rows[i][10], d.rows[i][11]));
    }
  EXPECT_GT(before, 0.05);
  ASSERT_GT(d.rows.size(), last_alive + 150);
  for (std::size_t i = last_alive + 1; i < d.rows.size(); ++i) {
    EXPECT_LE(d.rows[i][12], d.rows[i - 1][12]) << "gain must only fall, row " << i;
  }
  EXPECT_EQ(d.rows.back()[12], 0.0);
  EXPECT_EQ(std::hypot(d.rows.back()[9], d.rows.back()[10], d.rows.back()[11]), 0.0);
  // frames the sim wrote before it died are whole
  for (const auto& e : fs::directory_iterator(dir + "/rec/frames")) {
    if (e.path().extension() != ".png") continue;
    EXPECT_TRUE(read_png(e.path().string())) << e.path();
  }
  EXPECT_FALSE(fs::exists("/dev/shm/palpate-" + link));
}

TEST(DeviceLink, BadPosesAreRejectedCountedAndTheLastGoodPoseKept) {
  const std::string dir = fresh("inject"), link = test::link_name("inject");
  const std::string scene = test::device_scene("dev_inject", 1.5, {{"watchdog_ms", 50}});
  Child dev = start_device(link, scene, dir, "a", {"--inject", "nan@0.3,outside@0.5,jump@0.7"});
  ASSERT_TRUE(dev.wait_for_output("serving shm", kWait_s));
  Child rec = start_record(link, scene, dir, false);
  ASSERT_EQ(rec.wait(kWait_s * 2), 0) << rec.output();
  dev.signal(SIGTERM);
  ASSERT_EQ(dev.wait(kWait_s), 0) << dev.output();

  const auto s = summary(dir);
  EXPECT_GE(s["device"]["rejected_nonfinite"].get<int64_t>(), 1) << s["device"].dump();
  EXPECT_GE(s["device"]["rejected_outside"].get<int64_t>(), 1) << s["device"].dump();
  EXPECT_GE(s["device"]["rejected_speed"].get<int64_t>(), 1) << s["device"].dump();
  // the driver refuses them itself: the servo sees ticks without a reading
  EXPECT_GE(s["rejected_inputs"].get<int64_t>() + s["no_readings"].get<int64_t>(), 3);
  const Csv h = test::read_csv(dir + "/rec/haptic.csv");
  const auto x = static_cast<std::size_t>(h.col("tool_x_m"));
  for (std::size_t i = 0; i < h.rows.size(); ++i)
    for (std::size_t k = 0; k < 3; ++k) {
      ASSERT_TRUE(std::isfinite(h.rows[i][x + k])) << "row " << i;
      ASSERT_LT(std::abs(h.rows[i][x + k]), 0.2) << "row " << i;  // the workspace
      // the 5 cm jump never reached the servo: the hand moves well under 1 cm per tick
      if (i > 0) {
        ASSERT_LT(std::abs(h.rows[i][x + k] - h.rows[i - 1][x + k]), 0.01) << "row " << i;
      }
    }
  expect_complete(dir, s, 0);
}

}  // namespace
}  // namespace palpate
