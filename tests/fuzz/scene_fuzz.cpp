// libFuzzer target: scene JSON text -> parse_scene(): a Scene or a one-line error, never a crash, a hang or
// undefined behaviour; a parsed scene holds only values within the ranges the parser promises.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "core/limits.h"
#include "core/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto r = palpate::parse_scene(text, "fuzz.json");
  if (!r) {
    // an error is one line naming the scene
    const std::string& m = r.error().message;
    if (m.rfind("scene 'fuzz.json': ", 0) != 0 || m.find('\n') != std::string::npos) std::abort();
    return 0;
  }
  const palpate::Scene& s = r.value();
  const bool ok = !s.trajectory.empty() && s.trajectory.size() <= static_cast<std::size_t>(palpate::kMaxKeyframes) &&
                  s.lattice.level >= 1 && s.lattice.level <= s.grid_levels && s.grid_levels <= palpate::kMaxGridLevels &&
                  std::isfinite(s.duration_s) && s.duration_s > 0 &&
                  int64_t{s.render.width} * s.render.height <= palpate::kMaxImagePixels;
  if (!ok) std::abort();
  for (std::size_t i = 1; i < s.trajectory.size(); ++i)
    if (!(s.trajectory[i].t_s > s.trajectory[i - 1].t_s) || !s.trajectory[i].pos_m.allFinite()) std::abort();
  return 0;
}
