#pragma once
/// RunSchedule: the order in which a run's servo ticks and sim frames met, as its haptic.csv records it (each tick's
/// `frame`, the sim frame that took its sample, and `model_frame`, the frame whose surface patch it felt). A realtime
/// run's order follows the wall clock; a lockstep replay that follows its schedule feeds every frame the samples that
/// run's frame took and lets every tick feel the patch that run's tick felt, so the replay is the session, tick for
/// tick, not a fresh run of the same hand.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/result.h"

namespace palpate {

/// A run's ticks and frames in the order they met. Plain data.
struct RunSchedule {
  /// One sim frame of the run.
  struct Frame {
    int64_t index = 0;          ///< the frame's index (its scene time is Rates::frame_time_s(index))
    int64_t drain_to_tick = -1; ///< it takes the queued samples up to this tick
    std::size_t before = 0;     ///< it runs before ticks[before] (ticks.size(): after the last tick)
  };
  std::vector<int64_t> ticks;   ///< the servo ticks the run made, in order (a realtime servo skips ticks it missed)
  std::vector<Frame> frames;    ///< the frames, in order
};

/// One tick of a recorded log as the schedule reads it.
struct ScheduledTick {
  int64_t tick = 0;         ///< servo tick index
  int64_t frame = -1;       ///< the frame that took its sample (-1: taken after the run's last frame)
  int64_t model_frame = -1; ///< the frame whose patch it felt (-1: none yet)
};

/// The schedule of a log's ticks (in log order): every frame from 0 to the last the log names ran, but those in
/// `skipped` (a realtime run's frames skipped a whole period late); each runs after the last tick it took and before
/// the first tick that felt it, and a frame never felt (one that took nothing while the servo stalled) just before
/// the next frame. Frames after the last one the log names are not run. An error when the columns contradict
/// each other (ticks not increasing, a frame felt before it took its samples, frames out of order, a skipped frame
/// named); `what` names the log in it.
Result<RunSchedule> make_run_schedule(const std::vector<ScheduledTick>& ticks, const std::vector<int64_t>& skipped,
                                      const std::string& what);

}  // namespace palpate
