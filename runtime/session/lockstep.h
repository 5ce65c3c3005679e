#pragma once
/// The lockstep driver: one loop that advances a virtual clock through servo ticks and the frames due between
/// them, so a run is reproducible bit for bit. Session::run_lockstep drives a session with it.

#include <cstdint>

#include "core/rates.h"
#include "core/run_schedule.h"

namespace palpate {

/// Runs rates.ticks(duration_s) servo ticks; before the tick at time t, every frame whose time is <= t runs;
/// frames left after the last tick run at the end. on_frame(index, t_s) and on_tick(index, t_s) are called in
/// that order, on the calling thread.
template <class OnFrame, class OnTick>
void run_lockstep(const Rates& rates, double duration_s, OnFrame&& on_frame, OnTick&& on_tick) {
  const int64_t ticks = rates.ticks(duration_s);
  const int64_t frames = rates.frames(duration_s);
  int64_t next_frame = 0;
  for (int64_t i = 0; i < ticks; ++i) {
    const double t = rates.tick_time_s(i);
    while (next_frame < frames && rates.frame_time_s(next_frame) <= t + 1e-12) {
      on_frame(next_frame, rates.frame_time_s(next_frame));
      ++next_frame;
    }
    on_tick(i, t);
  }
  for (; next_frame < frames; ++next_frame) on_frame(next_frame, rates.frame_time_s(next_frame));
}

/// Runs a recorded run's ticks and frames in the order they met (core/run_schedule.h): on_frame(index, t_s,
/// drain_to_tick) before the tick it preceded, on_tick(index, t_s) for each recorded tick; times from `rates` as
/// run_lockstep's.
template <class OnFrame, class OnTick>
void run_scheduled(const Rates& rates, const RunSchedule& schedule, OnFrame&& on_frame, OnTick&& on_tick) {
  std::size_t next_frame = 0;
  for (std::size_t r = 0; r <= schedule.ticks.size(); ++r) {
    for (; next_frame < schedule.frames.size() && schedule.frames[next_frame].before <= r; ++next_frame) {
      const RunSchedule::Frame& f = schedule.frames[next_frame];
      on_frame(f.index, rates.frame_time_s(f.index), f.drain_to_tick);
    }
    if (r < schedule.ticks.size()) on_tick(schedule.ticks[r], rates.tick_time_s(schedule.ticks[r]));
  }
}

}  // namespace palpate
