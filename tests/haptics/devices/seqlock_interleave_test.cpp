// The seqlock readers against a write that lands in the middle of their copy, made deterministic: this file
// interposes on the readers' field loads (PALPATE_SHIM_LD) and runs a whole writer record between two of them.
// A reader that does not check the lock again after copying returns a torn record here on every run.
#include <cstdint>
#include <functional>

namespace {
std::function<void()> g_between_loads;  // runs once, before the reader's n-th field load
int g_loads_until_write = -1;

void before_load() {
  if (g_loads_until_write < 0) return;
  if (g_loads_until_write-- == 0 && g_between_loads) g_between_loads();
}
}  // namespace

#define PALPATE_SHIM_LD(src, dst) (before_load(), __atomic_load(&(src), &(dst), __ATOMIC_RELAXED))
#include "haptics/shim/palpate_shim.h"

#include <gtest/gtest.h>

namespace {

palpate_shim_pose pose_of(uint64_t i) {
  palpate_shim_pose p{};
  p.seq = i;
  p.time_ns = static_cast<int64_t>(i) * 1000;
  for (double& v : p.pos_m) v = static_cast<double>(i);
  for (double& v : p.quat_wxyz) v = static_cast<double>(i);
  p.buttons = i;
  return p;
}

bool whole(const palpate_shim_pose& p) {
  const auto i = static_cast<double>(p.seq);
  bool same = p.time_ns == static_cast<int64_t>(p.seq) * 1000 && p.buttons == p.seq;
  for (double v : p.pos_m) same = same && v == i;
  for (double v : p.quat_wxyz) same = same && v == i;
  return same;
}

class Interleave : public ::testing::TestWithParam<int> {
 protected:
  void TearDown() override {
    g_loads_until_write = -1;
    g_between_loads = nullptr;
  }
};
using PoseInterleave = Interleave;
using ForceInterleave = Interleave;

// A pose record has 10 fields; the write lands before load 1..9 of the first copy (after load 0, the seq).
TEST_P(PoseInterleave, PoseWrittenMidCopyIsReadAgainWhole) {
  palpate_shim_pose_slot slot{};
  const palpate_shim_pose first = pose_of(1);
  palpate_shim_write_pose(&slot, &first);
  const palpate_shim_pose second = pose_of(2);
  g_between_loads = [&] { palpate_shim_write_pose(&slot, &second); };
  g_loads_until_write = GetParam();
  palpate_shim_pose got{};
  ASSERT_EQ(palpate_shim_read_pose(&slot, &got, 4), 1);
  EXPECT_TRUE(whole(got)) << "torn copy: seq " << got.seq << ", time " << got.time_ns << ", x " << got.pos_m[0]
                          << ", buttons " << got.buttons;
  EXPECT_EQ(got.seq, 2u);  // the copy that raced the write was dropped, the retry read the new record
}

// A force record has 7 fields: the write lands before load 1..6.
TEST_P(ForceInterleave, ForceWrittenMidCopyIsReadAgainWhole) {
  palpate_shim_force_slot slot{};
  auto force_of = [](uint64_t i) {
    palpate_shim_force f{};
    f.seq = i;
    f.time_ns = static_cast<int64_t>(i);
    for (double& v : f.force_N) v = static_cast<double>(i);
    f.pose_seq = i;
    f.pose_time_ns = static_cast<int64_t>(i);
    return f;
  };
  const palpate_shim_force first = force_of(1);
  palpate_shim_write_force(&slot, &first);
  const palpate_shim_force second = force_of(2);
  g_between_loads = [&] { palpate_shim_write_force(&slot, &second); };
  g_loads_until_write = GetParam();
  palpate_shim_force got{};
  ASSERT_EQ(palpate_shim_read_force(&slot, &got, 4), 1);
  const auto i = static_cast<double>(got.seq);
  EXPECT_EQ(got.seq, 2u);
  EXPECT_EQ(static_cast<double>(got.time_ns), i);
  for (double v : got.force_N) EXPECT_EQ(v, i);
  EXPECT_EQ(got.pose_seq, got.seq);
}

INSTANTIATE_TEST_SUITE_P(EveryField, PoseInterleave, ::testing::Range(1, 10));
INSTANTIATE_TEST_SUITE_P(EveryField, ForceInterleave, ::testing::Range(1, 7));

TEST(PoseInterleave, AWriterThatNeverFinishesGivesNoCopy) {
  palpate_shim_pose_slot slot{};
  const palpate_shim_pose first = pose_of(1), third = pose_of(3);
  palpate_shim_write_pose(&slot, &first);
  __atomic_store_n(&slot.lock, slot.lock + 1u, __ATOMIC_RELAXED);  // a writer died inside a record
  palpate_shim_pose got{};
  EXPECT_EQ(palpate_shim_read_pose(&slot, &got, 16), 0);
  palpate_shim_write_pose(&slot, &third);  // the next write mends the lock
  ASSERT_EQ(palpate_shim_read_pose(&slot, &got, 1), 1);
  EXPECT_TRUE(whole(got));
  EXPECT_EQ(got.seq, 3u);
}

}  // namespace
