// make_run_schedule: a realtime run's order of ticks and frames, read back from what haptic.csv says of each tick.
#include "core/run_schedule.h"

#include <gtest/gtest.h>

namespace palpate {
namespace {

// A realtime run as it happens: frame 0 takes nothing and is felt from tick 1; frame 1 takes ticks 0..16, which
// felt nothing or frame 0, and is felt from tick 19 (the servo ticked twice while it computed); frame 2 was skipped
// (late); frame 3 takes ticks 17..33 but a tick missed (tick 25 is not in the log), and frame 4 ran right after
// it, taking nothing, before any tick felt frame 3: both run before tick 34, in order; ticks 34..36 are taken
// after the last frame.
std::vector<ScheduledTick> realtime_run() {
  std::vector<ScheduledTick> t;
  for (int64_t i = 0; i <= 36; ++i) {
    if (i == 25) continue;
    const int64_t frame = i <= 16 ? 1 : i <= 33 ? 3 : -1;
    const int64_t felt = i == 0 ? -1 : i < 19 ? 0 : i < 34 ? 1 : 4;
    t.push_back({i, frame, felt});
  }
  return t;
}

TEST(RunSchedule, FramesRunAfterTheTicksTheyTookAndBeforeTheFirstTickThatFeltThem) {
  auto s = make_run_schedule(realtime_run(), {2}, "log");
  ASSERT_TRUE(s) << s.error().message;
  const RunSchedule& r = s.value();
  ASSERT_EQ(r.ticks.size(), 36u);
  EXPECT_EQ(r.ticks[25], 26);  // the missed tick is not made up
  ASSERT_EQ(r.frames.size(), 4u);
  // frame 0: nothing taken, felt from tick 1 (row 1)
  EXPECT_EQ(r.frames[0].index, 0);
  EXPECT_EQ(r.frames[0].drain_to_tick, -1);
  EXPECT_EQ(r.frames[0].before, 1u);
  // frame 1: ticks up to 16, felt from tick 19 (row 19)
  EXPECT_EQ(r.frames[1].index, 1);
  EXPECT_EQ(r.frames[1].drain_to_tick, 16);
  EXPECT_EQ(r.frames[1].before, 19u);
  // frame 3 (never felt) runs just before frame 4, which is felt from tick 34 (row 33: tick 25 is missing)
  EXPECT_EQ(r.frames[2].index, 3);
  EXPECT_EQ(r.frames[2].drain_to_tick, 33);
  EXPECT_EQ(r.frames[2].before, 33u);
  EXPECT_EQ(r.frames[3].index, 4);
  EXPECT_EQ(r.frames[3].drain_to_tick, 33) << "a frame that took nothing takes nothing new";
  EXPECT_EQ(r.frames[3].before, 33u);
}

// Frame 2 not skipped: it ran while the servo stalled, took nothing and was never felt (it stepped the lattice all
// the same): it runs between frames 1 and 3, taking nothing new. A frame the log names cannot have been skipped.
TEST(RunSchedule, AFrameThatRanWhileTheServoStalledRunsInItsPlace) {
  auto s = make_run_schedule(realtime_run(), {}, "log");
  ASSERT_TRUE(s) << s.error().message;
  const RunSchedule& r = s.value();
  ASSERT_EQ(r.frames.size(), 5u);
  EXPECT_EQ(r.frames[2].index, 2);
  EXPECT_EQ(r.frames[2].drain_to_tick, 16);
  EXPECT_EQ(r.frames[2].before, 33u);
  EXPECT_EQ(r.frames[3].index, 3);
  auto named = make_run_schedule(realtime_run(), {3}, "log");
  ASSERT_FALSE(named);
  EXPECT_NE(named.error().message.find("frame 3 is named in the log but was skipped"), std::string::npos)
      << named.error().message;
}

TEST(RunSchedule, ALogThatContradictsItselfIsRefusedNamingTheTick) {
  {
    auto t = realtime_run();
    t[5].tick = 3;  // ticks not increasing
    auto s = make_run_schedule(t, {2}, "replay 'x.csv'");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("replay 'x.csv': tick 3 does not follow tick 4"), std::string::npos)
        << s.error().message;
  }
  {
    auto t = realtime_run();
    t[18].model_frame = 1;  // tick 18 felt frame 1, which took tick 16: fine; tick 10 feeling it is not
    t[10].model_frame = 1;
    auto s = make_run_schedule(t, {2}, "log");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("tick 11"), std::string::npos) << s.error().message;
  }
  {
    auto t = realtime_run();
    t[12].model_frame = 1;  // felt frame 1 before frame 1 took ticks 13..16
    for (std::size_t i = 13; i < 19; ++i) t[i].model_frame = 1;
    auto s = make_run_schedule(t, {2}, "log");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("frame 1 took tick 16"), std::string::npos) << s.error().message;
  }
  {
    // a frame index no run of these ticks could have reached is refused at once, not walked to
    auto s = make_run_schedule({{0, 1000000000000, -1}, {1, 1000000000000, -1}}, {}, "log");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("frame 1000000000000 is more frames than its 2 ticks could have met"),
              std::string::npos)
        << s.error().message;
  }
  {
    auto t = realtime_run();
    t[20].frame = -1;  // taken after the last frame, then a frame takes more
    auto s = make_run_schedule(t, {2}, "log");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("tick 21 was taken by frame 3"), std::string::npos) << s.error().message;
  }
}

}  // namespace
}  // namespace palpate
