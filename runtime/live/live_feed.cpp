#include "runtime/live/live_feed.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include "core/clock.h"

namespace palpate {
namespace {

// plot points the queue holds between two reads (the server takes them ten times a second): 30 s at 60 Hz
constexpr std::size_t kPointQueue = 1800;

}  // namespace

LiveFeed::LiveFeed(int width, int height, std::string scene, std::string mode)
    : width_(width), height_(height), scene_(std::move(scene)), mode_(std::move(mode)),
      slot_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4), points_(kPointQueue) {}

void LiveFeed::add_sample(const HapticSample& s) noexcept {
  const auto us = static_cast<int64_t>(s.wake_latency_us);
  wake_.add(us * 1000);
  ++ticks_seen_;
  // the runner skips whole periods after an overrun: the gap in tick numbers is what it skipped
  if (last_tick_ >= 0 && s.tick > last_tick_ + 1) overruns_ += s.tick - last_tick_ - 1;
  last_tick_ = s.tick;
  const auto f = static_cast<float>(s.force_N.norm());
  frame_force_N_ = std::max(frame_force_N_, f);
  max_force_N_ = std::max(max_force_N_, static_cast<double>(f));
  frame_wake_us_ = std::max(frame_wake_us_, s.wake_latency_us);
  frame_contact_ = static_cast<uint8_t>(s.contact);
}

void LiveFeed::offer_frame(int64_t index, const uint8_t* rgba) noexcept {
  if (!rgba || monotonic_ns() > want_until_ns_.load(std::memory_order_relaxed)) return;
  // a reader copying the previous frame keeps the slot: this frame is skipped, the next one goes in
  if (!slot_mutex_.try_lock()) return;
  std::memcpy(slot_.data(), rgba, slot_.size());
  slot_index_.store(index, std::memory_order_release);
  slot_mutex_.unlock();
}

void LiveFeed::end_frame(int64_t index, double t_s, double frame_ms, int64_t frames, int64_t frames_written,
                         int64_t frames_dropped) noexcept {
  if (finished_.load(std::memory_order_relaxed)) return;
  LivePoint p;
  p.frame = index;
  p.t_s = t_s;
  p.force_N = frame_force_N_;
  p.contact = frame_contact_;
  p.wake_max_us = frame_wake_us_;
  p.frame_ms = static_cast<float>(frame_ms);
  p.late_ms = static_cast<float>(static_cast<double>(late_ns_) * 1e-6);
  if (!points_.try_push(p)) points_dropped_.fetch_add(1, std::memory_order_relaxed);
  frame_force_N_ = 0.0f;
  frame_wake_us_ = 0.0f;
  late_ns_ = 0;

  LiveFigures& f = figures_.write_buffer();
  f.frames = frames;
  f.frames_written = frames_written;
  f.frames_dropped = frames_dropped;
  f.frames_late = frames_late_;
  f.servo_ticks = ticks_seen_;
  f.overruns = overruns_;
  f.servo_p50_us = wake_.quantile_us(0.5);
  f.servo_p99_us = wake_.quantile_us(0.99);
  f.t_s = t_s;
  f.max_force_N = max_force_N_;
  f.finished = false;
  figures_.publish();
}

void LiveFeed::finish(const LiveFigures& final_figures) noexcept {
  figures_.write_buffer() = final_figures;
  figures_.write_buffer().finished = true;
  figures_.publish();
  finished_.store(true, std::memory_order_relaxed);
}

void LiveFeed::want_frames_until(int64_t until_ns) noexcept {
  int64_t cur = want_until_ns_.load(std::memory_order_relaxed);
  while (cur < until_ns && !want_until_ns_.compare_exchange_weak(cur, until_ns, std::memory_order_relaxed)) {
  }
}

int64_t LiveFeed::copy_frame(int64_t after, std::vector<uint8_t>* rgba) {
  if (slot_index_.load(std::memory_order_acquire) <= after) return -1;
  std::lock_guard<std::mutex> lock(slot_mutex_);
  const int64_t index = slot_index_.load(std::memory_order_relaxed);
  if (index <= after) return -1;
  rgba->assign(slot_.begin(), slot_.end());
  return index;
}

void LiveFeed::take_points(std::vector<LivePoint>* out) {
  LivePoint p;
  while (points_.try_pop(&p)) out->push_back(p);
}

LiveFigures LiveFeed::figures() { return figures_.read(); }

}  // namespace palpate
