#pragma once
/// Feel figures: what a hand on the device feels of a servo tick log — tick-to-tick force steps inside contact
/// against what the device's own motion explains, ripple while sliding, the steps at contact events, the share of
/// the force's variation above 100 Hz and the energy put into the hand. Pure functions of a trace (no I/O).

#include <array>
#include <cstdint>
#include <vector>

#include "core/rates.h"
#include "core/types.h"
#include "haptics/servo/haptic_sample.h"

namespace palpate {

/// Events a tick may start; a tick can carry several.
enum class FeelEvent : int { kEntry, kRelease, kGrab, kGrabRelease, kRegion, kCut, kCount };
/// Number of event kinds.
inline constexpr int kFeelEvents = static_cast<int>(FeelEvent::kCount);
/// Names as the table and the JSON give them.
inline constexpr const char* kFeelEventNames[kFeelEvents] = {"entry", "release", "grab", "grab_release", "region",
                                                             "cut"};

/// One servo tick as the bench sees it. Plain data.
struct FeelTick {
  Vec3 tool_m = Vec3::Zero();   ///< device position P_t
  Vec3 force_N = Vec3::Zero();  ///< force sent
  ContactState contact = ContactState::kFree;
  bool region_changed = false;  ///< the first tick after a frame that placed or moved the lattice region
  bool cut = false;             ///< the first tick after a frame that cut springs
};

/// How the figures are taken. Plain data.
struct FeelSettings {
  double period_s = 1.0 / kDefaultServoRate_hz;  ///< servo period (the run's: bench feel sets it from the scene)
  double coupling_N_per_m = 300.0;    ///< k_c: a device step dx explains a force step k_c |dx|
  double damping_Ns_per_m = 0.5;      ///< b_c: a velocity step dv explains b_c |dv|
  double step_threshold_N = 0.1;      ///< steps counted above this
  double excess_threshold_N = 0.02;   ///< steps beyond the explained part counted above this
  double event_window_s = 0.05;       ///< an event's steps are those of this long from it (kept out of steady contact)
  double trend_s = 0.02;              ///< the trend removed before ripple and flips (centred moving mean)
  double sliding_speed_m_per_s = 0.002;  ///< sliding: the device moves at least this fast (over the trend window)
  double flip_floor_N = 0.005;        ///< a lateral force flip counts when both ticks' lateral force exceed this
  double buzz_hz = 100.0;             ///< energy above this frequency is the buzz share
  int min_run_ticks = 128;            ///< contact stretches shorter than this are left out of the spectrum
  double jump_limit_N_per_tick = 0.0; ///< the servo's jump limit: what an event tick's step may exceed by (all ticks)
};

/// The steps of one kind of event. Plain data.
struct FeelEventFigures {
  int64_t count = 0;        ///< events of this kind
  double max_step_N = 0.0;  ///< largest |dF| on an event tick
  double max_excess_N = 0.0;///< largest |dF| beyond the explained part on any tick of the event windows
};

/// The figures of one trace. Plain data.
struct FeelFigures {
  int64_t ticks = 0, contact_ticks = 0;  ///< ticks, ticks in contact
  int64_t steady_ticks = 0;              ///< contact ticks after a contact tick of the same kind, outside event windows
  double max_step_N = 0.0, p99_step_N = 0.0;  ///< steady contact: |F_i - F_(i-1)|
  int64_t steps_over = 0;                ///< steady steps above step_threshold_N
  double max_excess_N = 0.0;             ///< steady: largest step beyond k_c |dP_t| + b_c |dv|
  int64_t excess_over = 0;               ///< steady steps whose excess is above excess_threshold_N
  int64_t lateral_flips = 0;             ///< steady ticks whose lateral force (off the trend's direction) reversed
  // every contact tick and the tick after one, event windows included: a step above step_threshold_N beyond the
  // device's motion by more than excess_threshold_N (and, on an event's own tick, the jump limit besides)
  int64_t wild_steps = 0;                ///< such ticks
  int64_t excess_ticks = 0;              ///< ticks (the same ones) beyond the motion by more than excess_threshold_N
  double max_wild_excess_N = 0.0;        ///< the largest such excess (less an event tick's jump limit)
  int64_t sliding_ticks = 0;             ///< steady ticks while the device slides
  double ripple = 0.0;                   ///< sliding: peak-to-peak of |F| less its trend, over the trend's mean
  double buzz_share = 0.0;               ///< share of the contact force's variation energy above buzz_hz
  double energy_into_hand_J = 0.0;       ///< sum of F . dP_t (> 0: the device did net work on the hand)
  std::array<FeelEventFigures, kFeelEvents> events{};  ///< per event kind
  std::vector<double> spectrum_hz, spectrum_power;     ///< longest contact stretch: power per frequency bin (N^2)
};

/// The events starting at each tick: contact transitions from the contact states, region and cut flags as given.
std::vector<std::array<bool, kFeelEvents>> feel_events(const std::vector<FeelTick>& trace);

/// All figures of a trace.
FeelFigures feel_figures(const std::vector<FeelTick>& trace, const FeelSettings& settings);

}  // namespace palpate
