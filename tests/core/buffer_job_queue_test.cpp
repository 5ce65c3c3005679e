// BufferJobQueue: the bounded job queue of the PNG and video writers: FIFO, bounded by its buffers, closing drains.
#include <gtest/gtest.h>

#include <set>
#include <thread>
#include <vector>

#include "core/buffer_job_queue.h"

namespace palpate {
namespace {

struct Job {
  int index = 0;
  uint8_t* buffer = nullptr;
};

TEST(BufferJobQueue, IsFifoAndBoundedByItsBuffers) {
  BufferJobQueue<Job> q(2, 16);
  uint8_t* a = q.acquire(false);
  uint8_t* b = q.acquire(false);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_NE(a, b);
  EXPECT_TRUE(q.owns(a));
  uint8_t outside[16];
  EXPECT_FALSE(q.owns(outside));
  EXPECT_EQ(q.acquire(false), nullptr);  // both out
  EXPECT_TRUE(q.push({1, a}));
  EXPECT_TRUE(q.push({2, b}));
  Job j;
  ASSERT_TRUE(q.pop(&j));
  EXPECT_EQ(j.index, 1);
  EXPECT_EQ(j.buffer, a);
  q.release(j.buffer);
  EXPECT_EQ(q.acquire(false), a);  // free again once released
}

TEST(BufferJobQueue, ClosingDrainsWhatWasQueuedAndRefusesTheRest) {
  BufferJobQueue<Job> q(3, 8);
  uint8_t* a = q.acquire(false);
  uint8_t* b = q.acquire(false);
  ASSERT_TRUE(q.push({7, a}));
  q.close();
  EXPECT_EQ(q.acquire(true), nullptr);  // does not wait once closed
  EXPECT_FALSE(q.push({8, b}));         // refused; its buffer is free again
  Job j;
  ASSERT_TRUE(q.pop(&j));
  EXPECT_EQ(j.index, 7);
  EXPECT_FALSE(q.pop(&j));
}

TEST(BufferJobQueue, EveryJobReachesOneWorkerOnceThroughFewBuffers) {
  constexpr int kJobs = 2000;
  BufferJobQueue<Job> q(3, 4);
  std::vector<int> seen[2];
  std::vector<std::thread> workers;
  for (int w = 0; w < 2; ++w)
    workers.emplace_back([&q, &seen, w] {
      Job j;
      while (q.pop(&j)) {
        seen[w].push_back(j.index);
        q.release(j.buffer);
      }
    });
  for (int i = 0; i < kJobs; ++i) {
    uint8_t* buf = q.acquire(true);
    ASSERT_NE(buf, nullptr);
    ASSERT_TRUE(q.push({i, buf}));
  }
  q.close();
  for (auto& t : workers) t.join();
  std::set<int> all(seen[0].begin(), seen[0].end());
  all.insert(seen[1].begin(), seen[1].end());
  EXPECT_EQ(all.size(), static_cast<std::size_t>(kJobs));
  EXPECT_EQ(seen[0].size() + seen[1].size(), static_cast<std::size_t>(kJobs));
  // each worker takes jobs in the order they were queued
  for (const auto& s : seen)
    for (std::size_t i = 1; i < s.size(); ++i) EXPECT_LT(s[i - 1], s[i]);
}

}  // namespace
}  // namespace palpate
