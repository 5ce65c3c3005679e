#pragma once
/// The lockstep driver: one loop that advances a virtual clock through servo ticks and the frames due between
/// them, so a run is reproducible bit for bit. Session::run_lockstep drives a session with it.

#include <cstdint>

#include "core/rates.h"

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
    const double t = static_cast<double>(i) / rates.servo_hz;
    while (next_frame < frames && static_cast<double>(next_frame) / rates.frame_hz <= t + 1e-12) {
      on_frame(next_frame, static_cast<double>(next_frame) / rates.frame_hz);
      ++next_frame;
    }
    on_tick(i, t);
  }
  for (; next_frame < frames; ++next_frame) on_frame(next_frame, static_cast<double>(next_frame) / rates.frame_hz);
}

}  // namespace palpate
