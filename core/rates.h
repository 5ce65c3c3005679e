#pragma once
/// Rates: the session's two clocks, servo ticks and sim/render frames per second, in one place. A Scene holds the
/// one Rates of a run (Scene::rates, command-line overrides applied once by the record plan); every part that needs
/// a rate or a period reads it from there and keeps no copy of it nor any value derived from it.

#include <cmath>
#include <cstdint>
#include <numbers>

namespace palpate {

/// Servo ticks per second when a scene does not say (key servo.rate_hz).
inline constexpr double kDefaultServoRate_hz = 1000.0;
/// Sim/render frames per second when a scene does not say.
inline constexpr double kDefaultFrameRate_hz = 60.0;

/// How often the servo ticks and the sim/render stage runs; plain data, read by every part that needs a rate
/// (device, servo, passivity guard, frame stage, lockstep driver, video).
struct Rates {
  double servo_hz = kDefaultServoRate_hz;  ///< servo ticks per second (scene-second in lockstep)
  double frame_hz = kDefaultFrameRate_hz;  ///< sim/render frames per second

  /// Servo period, seconds.
  double servo_period_s() const { return 1.0 / servo_hz; }
  /// Frame period, seconds.
  double frame_period_s() const { return 1.0 / frame_hz; }
  /// Scene time of servo tick i: the one formula every driver uses (lockstep, realtime, a replay), so the servo
  /// sees the same times, to the bit, whichever drove it.
  double tick_time_s(int64_t i) const { return static_cast<double>(i) / servo_hz; }
  /// Scene time of frame f (as tick_time_s, one formula for every driver).
  double frame_time_s(int64_t f) const { return static_cast<double>(f) / frame_hz; }
  /// Servo ticks in duration_s.
  int64_t ticks(double duration_s) const { return std::llround(duration_s * servo_hz); }
  /// Frames in duration_s (a frame at each frame boundary before the end).
  int64_t frames(double duration_s) const { return static_cast<int64_t>(std::ceil(duration_s * frame_hz - 1e-9)); }
  /// Frames per second as the video encoder takes it (whole frames per second).
  int video_fps() const { return static_cast<int>(std::lround(frame_hz)); }
};

/// The weight a one-pole low-pass with cut-off cutoff_hz gives each new sample when sampled every period_s:
/// y += w (x - y) with w = 1 - exp(-2 pi fc T), so the cut-off stays cutoff_hz whatever the sampling rate.
/// Thread: any (no allocation).
inline double low_pass_weight(double cutoff_hz, double period_s) noexcept {
  return -std::expm1(-2.0 * std::numbers::pi * cutoff_hz * period_s);
}

}  // namespace palpate
