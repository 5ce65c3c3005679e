// The browser driver on a fake clock: a page's first message anchors where the tool is and moves nothing, and no
// force flows until the pointer moves (connect, reload, takeover, a hidden tab's odd message, a blade's first press);
// the target moves between messages without steps, the hand model settles where its spring balances the device
// force (offset F / k), the watchdog fades the force to zero within stall_s + fade_s of a page's close or silence,
// and a servo driving it allocates nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "haptics/devices/browser_device.h"
#include "core/scene.h"
#include "haptics/servo/servo.h"
#include "support/alloc_counter.h"
#include "support/haptic_fixtures.h"

namespace palpate {
namespace {

int64_t g_now_ns = 0;
int64_t fake_clock() { return g_now_ns; }

// A device on the fake clock with a 10 cm square view plane (x, y in the world's x, z) and a stiff, heavy-damped hand.
struct Rig {
  explicit Rig(BrowserParams p = {}) : dev(DeviceSpecs{}, HandSpec{}, p, &link, test::kTestRates, fake_clock) {
    g_now_ns = 1'000'000'000;
    BrowserView v;
    v.right = Vec3::UnitX();
    v.up = Vec3::UnitZ();
    v.forward = Vec3::UnitY();
    dev.set_view(v);
  }
  void post(double x, double y, uint32_t buttons = 0, double depth = 0.0) {
    BrowserInput in;
    in.seq = ++seq;
    in.x = x;
    in.y = y;
    in.depth = depth;
    in.buttons = buttons;
    in.received_ns = g_now_ns;
    in.session = session;
    link.post(in);
  }
  // a page's control that starts at (0, 0): anchored there, then engaged by a small move and back, so later
  // messages place the tool where the pointer is (the start is the view's centre)
  void engage(uint32_t buttons = 0) {
    DevicePose p;
    post(0.0, 0.0, buttons);
    tick(&p);
    post(1e-3, 0.0, buttons);
    tick(&p);
    post(0.0, 0.0, buttons);
    tick(&p);
  }
  // one servo period on the fake clock, then a read; false when there was no reading
  bool tick(DevicePose* pose) {
    g_now_ns += 1'000'000;
    return dev.read(0.0, pose);
  }
  BrowserLink link;
  BrowserDevice dev;
  int64_t seq = 0;
  int64_t session = 1;
};

TEST(BrowserDevice, TheFirstMessageAnchorsWhereTheToolIsNoReadingUntilThePointerMoves) {
  Rig r;
  const Vec3 start(0.01, 0.0, 0.03);
  r.dev.set_start(start);
  DevicePose p;
  EXPECT_FALSE(r.tick(&p));
  // the page's first message is far from the tool (the view's centre): it anchors, moves nothing, gives no reading
  for (int i = 0; i < 200; ++i) {
    if (i % 16 == 0) r.post(0.0, 0.0);
    EXPECT_FALSE(r.tick(&p)) << "a reading before the pointer moved, tick " << i;
  }
  EXPECT_FALSE(r.link.feedback().engaged);
  // the pointer moves 0.2 to the right (1 cm on this view): the tool follows from where it was, by that much
  for (int i = 0; i < 1500; ++i) {
    if (i % 16 == 0) r.post(0.2, 0.0);
    ASSERT_TRUE(r.tick(&p)) << i;
    r.dev.write_force(Vec3::Zero());
  }
  EXPECT_NEAR(p.pos_m.x(), start.x() + 0.01, 1e-6);
  EXPECT_NEAR(p.pos_m.z(), start.z(), 1e-6);
  EXPECT_TRUE(r.link.feedback().engaged);
}

// A page that falls silent (a busy browser) past the watchdog and then sends a moved pointer: the motion is not lost
// (the tool goes where the pointer says, from the page's anchor), and the force comes back with it.
TEST(BrowserDevice, AMotionSentAfterAPauseIsNotLost) {
  Rig r;
  DevicePose p;
  r.engage();
  for (int i = 0; i < 200; ++i) {
    if (i % 16 == 0) r.post(0.0, 0.0);
    ASSERT_TRUE(r.tick(&p));
    r.dev.write_force(Vec3::Zero());
  }
  for (int i = 0; i < 600; ++i) r.tick(&p);  // silent: faded out
  EXPECT_FALSE(r.tick(&p));
  for (int i = 0; i < 1500; ++i) {
    if (i % 16 == 0) r.post(0.2, 0.0);
    ASSERT_TRUE(r.tick(&p)) << i;
    r.dev.write_force(Vec3::Zero());
  }
  EXPECT_NEAR(p.pos_m.x(), 0.01, 1e-6) << "0.2 of the view is 1 cm: the first message after the pause moved the tool";
}

// A press held 2 cm into a floor; then a new page takes control (a reload or a takeover) and sends, without any input,
// the pointer at the view's centre and the button down (a right press in cut mode) for a second. Returns the largest
// force change per tick and the largest force after the takeover, and the tool's travel; then the new page moves a
// little and the force comes back, ramped.
struct Takeover {
  double max_step_N = 0.0;       // the largest change of the servo's force from one tick to the next
  int64_t max_step_tick = 0;     // where
  double after_N = 0.0;          // the largest force once the old press faded out, until the new page moved
  double travel_m = 0.0;         // how far the tool went in that time
  bool button_before_move = false;
  double back_N = 0.0;           // the force once the new page moved
};

Takeover take_over(bool hidden_tab) {
  Rig r;
  r.dev.set_start(Vec3(0.0, 0.0, 0.01));
  test::ServoRig<BrowserDevice&> rig(test::static_surface_params(300.0), 64, test::kTestRates, r.dev);
  test::publish_floor(rig.tb.get());
  const Servo& servo = *rig.servo;
  Takeover out;
  Vec3 last = Vec3::Zero();
  int64_t tick = 0;
  auto step = [&] {
    g_now_ns += 1'000'000;
    rig.tick(tick);
    ++tick;
    const Vec3 f = servo.last_sample().force_N;
    if ((f - last).norm() > out.max_step_N) {
      out.max_step_N = (f - last).norm();
      out.max_step_tick = tick;
    }
    last = f;
  };
  // the first page: anchored at (0, 0.2), then down by 0.6 of the view (3 cm): 2 cm into the floor, held
  for (int i = 0; i < 1500; ++i) {
    if (i % 16 == 0) r.post(0.0, i < 16 ? 0.2 : -0.4);
    step();
  }
  EXPECT_GT(last.norm(), 1.0) << "the press";
  out.max_step_N = 0.0;  // the steps from here on: the takeover's (the press's own entry is the servo's business)
  // the old press fades out over the watchdog (the hand, pushed back less, sinks in a little): from then on nothing
  // may move or push
  Vec3 faded_at = Vec3::Zero();
  if (hidden_tab) {
    // the page falls silent (a background tab), then sends its unchanged pose about once a second
    for (int i = 0; i < 4000; ++i) {
      if (i > 0 && i % 1000 == 0) r.post(0.0, -0.4);
      step();
      if (i == 400) faded_at = servo.last_sample().tool_pos_m;
      if (i < 400) continue;
      out.after_N = std::max(out.after_N, servo.last_sample().force_N.norm());
      out.travel_m = std::max(out.travel_m, (servo.last_sample().tool_pos_m - faded_at).norm());
    }
  } else {
    // a new page's control: the centre, button down, every 16 ms for a second
    r.session = 2;
    r.seq = 0;
    for (int i = 0; i < 1000; ++i) {
      if (i % 16 == 0) r.post(0.0, 0.0, 1);
      step();
      out.button_before_move = out.button_before_move || (servo.last_sample().buttons & 1u) != 0;
      if (i == 150) faded_at = servo.last_sample().tool_pos_m;
      if (i < 150) continue;
      out.after_N = std::max(out.after_N, servo.last_sample().force_N.norm());
      out.travel_m = std::max(out.travel_m, (servo.last_sample().tool_pos_m - faded_at).norm());
      out.button_before_move = out.button_before_move || (servo.last_sample().buttons & 1u) != 0;
    }
    // it moves a little: the press comes back, ramped in
    for (int i = 0; i < 500; ++i) {
      if (i % 16 == 0) r.post(0.002, 0.0, 1);
      step();
    }
    out.back_N = last.norm();
  }
  return out;
}

TEST(BrowserDevice, APageTakingOverMidPressPushesNothingUntilItMovesThenRampsIn) {
  const Takeover t = take_over(false);
  const double jump_limit_N = Scene{}.device.jump_limit_N_per_tick;
  EXPECT_EQ(t.after_N, 0.0) << "force from a page that has not moved";
  EXPECT_LT(t.travel_m, 1e-6) << "the tool moved toward the new page's pointer";
  EXPECT_FALSE(t.button_before_move) << "the button (a blade) went down before the page moved";
  EXPECT_GT(t.back_N, 1.0) << "the press did not come back once the page moved";
  EXPECT_LE(t.max_step_N, 3.0 * jump_limit_N) << "a step in the force at tick " << t.max_step_tick;
}

TEST(BrowserDevice, AHiddenTabsOddMessageNeverPulsesTheForce) {
  const Takeover t = take_over(true);
  EXPECT_EQ(t.after_N, 0.0) << "a message a second from an unmoved page brought force back";
  EXPECT_LT(t.travel_m, 1e-6);
}

// A pointer moving at 0.1 m/s with messages every 12..22 ms: the target's step per tick stays near v dt (1e-4 m),
// where holding each message would step by v times the message gap (up to 2.2e-3 m).
double max_target_step(const BrowserParams& params) {
  Rig r(params);
  DevicePose p;
  const double v_view_per_s = 0.1 / 0.05;  // 0.1 m/s in view units
  const int gaps_ms[] = {16, 12, 22, 17, 14, 19, 16, 21, 13, 17};
  r.post(-1.0, 0.0);
  r.tick(&p);
  double x = -1.0, max_step = 0.0;
  Vec3 last = r.link.feedback().target_m;
  for (int k = 0; k < 60; ++k) {
    const int gap = gaps_ms[k % 10];
    for (int i = 0; i < gap; ++i) {
      r.tick(&p);
      r.dev.write_force(Vec3::Zero());
      const Vec3 target = r.link.feedback().target_m;
      if (k > 5) max_step = std::max(max_step, (target - last).norm());  // after the interval estimate settles
      last = target;
    }
    x += v_view_per_s * gap * 1e-3;
    r.post(x, 0.0);
  }
  return max_step;
}

TEST(BrowserDevice, TargetMovesBetweenMessagesWithoutSteps) {
  const double step = max_target_step(BrowserParams{});
  EXPECT_LT(step, 2.0 * 1e-4) << "the target steps more than twice v dt";
  EXPECT_GT(step, 0.5 * 1e-4);
  // without interpolation (a segment of 1 ns) the same pointer steps by a whole message gap
  BrowserParams held;
  held.min_interval_s = held.max_interval_s = 1e-9;
  EXPECT_GT(max_target_step(held), 1.0e-3);
}

TEST(BrowserDevice, HandSettlesWhereItsSpringBalancesTheForce) {
  Rig r;
  DevicePose p;
  const HandSpec hand;
  const Vec3 force(0.0, 0.0, 1.5);
  r.engage();
  for (int i = 0; i < 3000; ++i) {
    if (i % 16 == 0) r.post(0.0, 0.0);
    ASSERT_TRUE(r.tick(&p));
    r.dev.write_force(force);
  }
  // k (target - x) + F = 0: the handle sits F / k above the target
  EXPECT_NEAR(p.pos_m.z(), force.z() / hand.stiffness_N_per_m, 1e-6);
  EXPECT_NEAR(p.pos_m.x(), 0.0, 1e-9);
}

// The fade after the last message at time 0: full until `from_ms`, zero from from_ms + fade; returns the scale
// at every ms (-1 where there was no reading).
std::vector<double> fade_after(bool close_page) {
  Rig r;
  DevicePose p;
  r.engage(1);
  for (int i = 0; i < 400; ++i) {
    if (i % 16 == 0) r.post(0.0, 0.0, 1);
    r.tick(&p);
    r.dev.write_force(Vec3::Zero());
  }
  r.post(0.0, 0.0, 1);
  if (close_page) r.link.release();
  std::vector<double> scale;
  for (int i = 0; i < 600; ++i) scale.push_back(r.tick(&p) ? p.force_scale : -1.0);
  EXPECT_EQ(r.dev.counters().releases, close_page ? 1 : 0);
  EXPECT_EQ(r.dev.counters().stalls, 1) << "silent past stall_s once (closed or not)";
  return scale;
}

TEST(BrowserDevice, AClosedPageFadesTheForceOutOverFade) {
  const BrowserParams params;
  const auto s = fade_after(true);
  const int fade_ms = static_cast<int>(params.fade_s * 1e3);
  EXPECT_NEAR(s[fade_ms / 2 - 1], 0.5, 0.02);
  EXPECT_EQ(s[fade_ms], -1.0) << "no reading once faded out";
  for (int i = 1; i < fade_ms; ++i) EXPECT_LE(s[i], s[i - 1]) << i;
}

TEST(BrowserDevice, ASilentPageFadesTheForceOutWithinTheWatchdog) {
  const BrowserParams params;
  const auto s = fade_after(false);
  const int stall_ms = static_cast<int>(params.stall_s * 1e3), watchdog_ms = static_cast<int>(params.watchdog_s() * 1e3);
  EXPECT_EQ(s[stall_ms - 2], 1.0) << "full force while the page is within stall_s";
  EXPECT_GT(s[stall_ms + 10], 0.0);
  EXPECT_LT(s[stall_ms + 10], 1.0);
  EXPECT_EQ(s[watchdog_ms], -1.0) << "zero force at the watchdog time";
}

// The silent page's fade, tick by tick: full force until stall_s, then down in even steps of one fade_s-th a tick,
// never up, never a larger step (a click), and no reading from the watchdog time on.
TEST(BrowserDevice, ASilentPagesFadeIsARampNeverAStep) {
  const BrowserParams params;
  const auto s = fade_after(false);
  const int stall_ms = static_cast<int>(params.stall_s * 1e3), watchdog_ms = static_cast<int>(params.watchdog_s() * 1e3);
  const double step = 1e-3 / params.fade_s;  // the scale's change a 1 ms tick
  int fading = 0;
  for (int i = 1; i < watchdog_ms; ++i) {
    if (s[i] < 0.0) break;  // faded out: no reading
    EXPECT_LE(s[i], s[i - 1]) << i;
    EXPECT_LE(s[i - 1] - s[i], step + 1e-9) << i;
    fading += s[i] < 1.0;
  }
  EXPECT_GE(fading, static_cast<int>(params.fade_s * 1e3) - 2) << "the fade took fade_s";
  EXPECT_LE(fading, static_cast<int>(params.fade_s * 1e3));
  for (int i = watchdog_ms; i < static_cast<int>(s.size()); ++i) EXPECT_EQ(s[i], -1.0) << i;
  EXPECT_EQ(s[stall_ms - 2], 1.0);
}

// A servo pressing the pointer 2 cm into a floor: a force while the page is live, exactly zero from the watchdog time
// after its close on, and no allocation in 10,000 ticks with messages arriving.
TEST(BrowserDevice, ServoForceEndsAtTheWatchdogAndAllocatesNothing) {
  Rig r;
  r.dev.set_start(Vec3(0.0, 0.0, 0.01));
  test::ServoRig<BrowserDevice&> rig(test::static_surface_params(300.0), 64, test::kTestRates, r.dev);
  test::publish_floor(rig.tb.get());
  Servo& servo = *rig.servo;
  int64_t allocs = 0;
  {
    test::AllocationGuard guard;
    for (int i = 0; i < 10000; ++i) {
      // anchored at the view's centre 1 cm above the floor, then down to 2 cm below it (y is the world's z here)
      if (i % 16 == 0) r.post(0.0, i < 500 ? 0.2 : -0.4);
      g_now_ns += 1'000'000;
      rig.tick(i);
    }
    allocs = guard.count();
  }
  EXPECT_EQ(allocs, 0);
  const double pressed_N = servo.last_sample().force_N.z();
  EXPECT_GT(pressed_N, 1.0);
  r.link.release();
  const BrowserParams params;
  const int fade_ticks = static_cast<int>(params.fade_s * 1e3);
  double half = -1.0;
  for (int i = 0; i <= fade_ticks; ++i) {
    g_now_ns += 1'000'000;
    servo.tick(10000 + i, (10000 + i) * 1e-3);
    if (i == fade_ticks / 2) half = servo.last_sample().force_N.z();
  }
  EXPECT_GT(half, 0.2 * pressed_N) << "a ramp, not a step";
  EXPECT_LT(half, 0.8 * pressed_N);
  EXPECT_EQ(servo.last_sample().force_N.norm(), 0.0);
}

// The device's watchdog is the scene's (device.browser_stall_ms); one owner: BrowserParams' default is the default
// scene's.
TEST(BrowserDevice, TheWatchdogIsTheScenes) {
  Scene scene;
  scene.device.browser_stall_ms = 800.0;
  EXPECT_EQ(browser_params(scene).stall_s, 0.8);
  EXPECT_DOUBLE_EQ(browser_params(scene).watchdog_s(), 0.8 + BrowserParams{}.fade_s);
  EXPECT_EQ(BrowserParams{}.stall_s, browser_params(Scene{}).stall_s);
}

}  // namespace
}  // namespace palpate
