// libFuzzer target: haptic.csv text -> parse_haptic_csv(): rows or a one-line error; accepted rows are finite,
// in increasing time, with 32-bit button masks.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "haptics/devices/replay_device.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto r = palpate::parse_haptic_csv(text, "fuzz.csv");
  if (!r) {
    const std::string& m = r.error().message;
    if (m.rfind("replay 'fuzz.csv': ", 0) != 0 || m.find('\n') != std::string::npos) std::abort();
    return 0;
  }
  const auto& rows = r.value();
  if (rows.empty()) std::abort();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!std::isfinite(rows[i].t_s) || !rows[i].pos_m.allFinite()) std::abort();
    if (i > 0 && !(rows[i].t_s > rows[i - 1].t_s)) std::abort();
    // the controls: a known mode, a positive stiffness, a radius within a metre, never going back
    const palpate::Controls& c = rows[i].controls;
    if (c.seq < 0 || !(c.stiffness_scale > 0.0) || !(c.tool_radius_m >= 0.0 && c.tool_radius_m <= 1.0) || c.resets < 0 ||
        static_cast<int>(c.mode) < 0 || static_cast<int>(c.mode) > 2)
      std::abort();
    if (i > 0 && c.seq < rows[i - 1].controls.seq) std::abort();
  }
  // the device plays them back: every reading it gives is one of the rows
  palpate::DeviceSpecs specs;
  palpate::ReplayDevice dev(specs, rows);
  palpate::DevicePose pose;
  for (double t : {rows.front().t_s - 1.0, rows.front().t_s, rows.back().t_s, rows.back().t_s + 1.0})
    if (dev.read(t, &pose) && !pose.pos_m.allFinite()) std::abort();
  return 0;
}
