#include "core/run_schedule.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>

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
  // (frame, its last tick taken) and (frame, its first tick felt), each in increasing frame order (checked below)
  std::vector<std::pair<int64_t, std::size_t>> taken, felt;
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
      if (taken.empty() || taken.back().first != t.frame) taken.emplace_back(t.frame, r);
      else taken.back().second = r;
    }
    if (t.model_frame >= 0) {
      if (t.model_frame < last_felt)
        return make_error(what, ": tick ", std::to_string(t.tick), " felt frame ", std::to_string(t.model_frame),
                          " after a tick felt frame ", std::to_string(last_felt));
      if (t.model_frame > last_felt) felt.emplace_back(t.model_frame, r);
      last_felt = t.model_frame;
    } else if (last_felt >= 0) {
      return make_error(what, ": tick ", std::to_string(t.tick), " felt no frame after a tick felt frame ",
                        std::to_string(last_felt));
    }
  }
  // the frames the log names, in order
  std::vector<Seen> seen;
  for (std::size_t i = 0, j = 0; i < taken.size() || j < felt.size();) {
    const int64_t f = std::min(i < taken.size() ? taken[i].first : INT64_MAX, j < felt.size() ? felt[j].first : INT64_MAX);
    Seen n{f};
    if (i < taken.size() && taken[i].first == f) n.last_taken = taken[i++].second;
    if (j < felt.size() && felt[j].first == f) n.first_felt = felt[j++].second;
    seen.push_back(n);
  }
  // the frames that ran and neither took a sample nor were felt (the servo stalled): every index up to the last
  // named, but the skipped ones. Frames come at 60 Hz and ticks at 100 Hz or more: a log naming more frames than its
  // ticks could have met (16 a tick, and a thousand more) is refused, not walked
  std::vector<int64_t> skip(skipped);
  std::sort(skip.begin(), skip.end());
  const int64_t last = seen.empty() ? -1 : seen.back().index;
  if (last > 16 * static_cast<int64_t>(ticks.size()) + 1024)
    return make_error(what, ": frame ", std::to_string(last), " is more frames than its ", std::to_string(ticks.size()),
                      " ticks could have met");
  for (const Seen& f : seen)
    if (std::binary_search(skip.begin(), skip.end(), f.index))
      return make_error(what, ": frame ", std::to_string(f.index), " is named in the log but was skipped");
  std::vector<Seen> all;
  all.reserve(static_cast<std::size_t>(last + 1));
  std::size_t named = 0;
  for (int64_t f = 0; f <= last; ++f) {
    if (named < seen.size() && seen[named].index == f) all.push_back(seen[named++]);
    else if (!std::binary_search(skip.begin(), skip.end(), f)) all.push_back(Seen{f});
  }
  seen.swap(all);
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
