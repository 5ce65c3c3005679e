#include "core/run_schedule.h"

#include <algorithm>
#include <limits>

namespace palpate {

Result<RunSchedule> make_run_schedule(const std::vector<ScheduledTick>& ticks, const std::vector<int64_t>& skipped,
                                      const std::string& what) {
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  RunSchedule s;
  s.ticks.reserve(ticks.size());
  // frame index -> (its last tick taken, its first tick felt), as row positions
  struct Seen {
    int64_t index;
    std::size_t last_taken = kNone, first_felt = kNone;
  };
  std::vector<Seen> seen;
  auto at = [&seen](int64_t f) -> Seen& {
    auto it = std::lower_bound(seen.begin(), seen.end(), f, [](const Seen& a, int64_t b) { return a.index < b; });
    if (it == seen.end() || it->index != f) it = seen.insert(it, Seen{f});
    return *it;
  };
  int64_t last_taken_by = -1, last_felt = -1;
  bool after_run = false;  // a sample taken after the last frame: every later one is too
  for (std::size_t r = 0; r < ticks.size(); ++r) {
    const ScheduledTick& t = ticks[r];
    if (r > 0 && t.tick <= ticks[r - 1].tick)
      return make_error(what, ": tick ", std::to_string(t.tick), " does not follow tick ", std::to_string(ticks[r - 1].tick));
    s.ticks.push_back(t.tick);
    if (t.frame < 0) {
      after_run = true;
    } else {
      if (after_run || t.frame < last_taken_by)
        return make_error(what, ": tick ", std::to_string(t.tick), " was taken by frame ", std::to_string(t.frame),
                          " after a later frame took an earlier tick");
      last_taken_by = t.frame;
      at(t.frame).last_taken = r;
    }
    if (t.model_frame >= 0) {
      if (t.model_frame < last_felt)
        return make_error(what, ": tick ", std::to_string(t.tick), " felt frame ", std::to_string(t.model_frame),
                          " after a tick felt frame ", std::to_string(last_felt));
      if (t.model_frame > last_felt) at(t.model_frame).first_felt = r;
      last_felt = t.model_frame;
    } else if (last_felt >= 0) {
      return make_error(what, ": tick ", std::to_string(t.tick), " felt no frame after a tick felt frame ",
                        std::to_string(last_felt));
    }
  }
  // the frames that ran and neither took a sample nor were felt (the servo stalled): every index up to the last
  // named, but the skipped ones
  std::vector<int64_t> skip(skipped);
  std::sort(skip.begin(), skip.end());
  const int64_t last = seen.empty() ? -1 : seen.back().index;
  for (const Seen& f : seen)
    if (std::binary_search(skip.begin(), skip.end(), f.index))
      return make_error(what, ": frame ", std::to_string(f.index), " is named in the log but was skipped");
  for (int64_t f = 0; f < last; ++f)
    if (!std::binary_search(skip.begin(), skip.end(), f)) at(f);
  // a frame never felt runs just before the next frame (or after the last tick)
  s.frames.resize(seen.size());
  std::size_t next_before = ticks.size();
  for (std::size_t k = seen.size(); k-- > 0;) {
    const Seen& f = seen[k];
    if (f.first_felt != kNone) next_before = f.first_felt;
    s.frames[k].index = f.index;
    s.frames[k].before = next_before;
  }
  int64_t drained = -1;
  for (std::size_t k = 0; k < seen.size(); ++k) {
    const Seen& f = seen[k];
    if (f.last_taken != kNone) {
      if (f.last_taken >= s.frames[k].before)
        return make_error(what, ": frame ", std::to_string(f.index), " took tick ", std::to_string(ticks[f.last_taken].tick),
                          ", which came after a tick that felt it or a later frame");
      drained = ticks[f.last_taken].tick;
    }
    s.frames[k].drain_to_tick = drained;
  }
  return s;
}

}  // namespace palpate
