#pragma once
/// Rates: the session's two clocks, servo ticks and sim/render frames per second, in one place.

#include <cmath>
#include <cstdint>

namespace palpate {

/// How often the servo ticks and the sim/render stage runs; plain data, handed to every part that needs a rate
/// (device, servo, passivity guard, frame stage, lockstep driver).
struct Rates {
  double servo_hz = 1000.0;  ///< servo ticks per second (scene-second in lockstep)
  double frame_hz = 60.0;    ///< sim/render frames per second

  /// Servo period, seconds.
  double servo_period_s() const { return 1.0 / servo_hz; }
  /// Frame period, seconds.
  double frame_period_s() const { return 1.0 / frame_hz; }
  /// Servo ticks in duration_s.
  int64_t ticks(double duration_s) const { return std::llround(duration_s * servo_hz); }
  /// Frames in duration_s (a frame at each frame boundary before the end).
  int64_t frames(double duration_s) const { return static_cast<int64_t>(std::ceil(duration_s * frame_hz - 1e-9)); }
};

}  // namespace palpate
