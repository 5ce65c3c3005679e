#pragma once
/// HapticSample: what the servo reports each tick to the sim thread (and to haptic.csv).

#include <cstdint>

#include "core/controls.h"
#include "core/types.h"

namespace palpate {

/// Contact state of the tool.
enum class ContactState : uint8_t { kFree = 0, kTouch = 1, kGrab = 2, kCut = 3 };

/// One servo tick. Plain data, copied through SpscQueue.
struct HapticSample {
  int64_t tick = 0;                    ///< servo tick number
  double t_s = 0.0;                    ///< scene time
  Vec3 tool_pos_m = Vec3::Zero();      ///< P_t, device position
  Vec3 proxy_pos_m = Vec3::Zero();     ///< P_s, contact point (== P_t when free)
  Vec3 god_pos_m = Vec3::Zero();       ///< the god-object where the surface holds it, before the contact model's
                                       ///< prediction moves P_s (== proxy_pos_m without one)
  Vec3 force_N = Vec3::Zero();         ///< force sent to the device
  ContactState contact = ContactState::kFree;
  int32_t contact_tri = -1;            ///< mesh triangle holding P_s (-1 when free)
  Vec3 contact_bary = Vec3::Zero();    ///< barycentric coordinates of P_s in that triangle
  uint32_t buttons = 0;                ///< device buttons
  uint8_t input_rejected = 0;          ///< 1 when the device reading was rejected this tick
  Vec3 blade_axis = Vec3::UnitZ();     ///< cut: unit direction of the blade edge from the tip (tool_pos_m) to the handle
  float wake_latency_us = 0.0f;        ///< realtime: how late the servo thread woke for this tick (0 on a virtual clock)
  double force_scale = 1.0;            ///< the driver's fade the force was scaled by (DevicePose::force_scale)
  int64_t model_frame = -1;            ///< the sim frame whose surface patch this tick felt (-1: none yet)
  int64_t drain_frame = -1;            ///< set by the sim thread: the frame that took this sample (-1: after the last)
  Controls controls{};                 ///< the controls the servo ran this tick under (seq 0: the scene's own)
};

}  // namespace palpate
