#pragma once
// The browser tests' look at a recording's frames: which file is the first or the newest, and where the model's
// surface moved between two frames.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#include "render/png_io.h"

namespace palpate::test {

// the newest frame file of a frames folder once `more` frames have been written after this call ("" if none came in 20 s)
inline std::string newest_frame_after(const std::string& frames_dir, int more) {
  auto newest = [&frames_dir](int64_t* count) {
    std::string path;
    int64_t best = -1;
    *count = 0;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(frames_dir, ec)) {
      const std::string name = e.path().filename().string();
      if (name.rfind("frame_", 0) != 0 || e.path().extension() != ".png") continue;
      ++*count;
      const int64_t n = std::atoll(name.c_str() + 6);
      if (n > best) best = n, path = e.path().string();
    }
    return path;
  };
  int64_t start = 0, now = 0;
  newest(&start);
  for (auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20); std::chrono::steady_clock::now() < end;) {
    const std::string path = newest(&now);
    if (now >= start + more) return path;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return {};
}

// the name of a frames folder's first frame (the lowest N of frame_N.png), "" when there is none
inline std::string first_frame_name(const std::string& frames_dir) {
  std::string name;
  int64_t lowest = -1;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(frames_dir, ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("frame_", 0) != 0 || e.path().extension() != ".png") continue;
    const int64_t k = std::atoll(n.c_str() + 6);
    if (lowest < 0 || k < lowest) lowest = k, name = n;
  }
  return name;
}

// A pixel of the model's surface (its shaded colour or its wireframe: blue-grey, channels in the mesh colour's
// proportions 0.66 : 0.73 : 0.84), not the background (near white), the tool (red in contact, blue while free) or
// the proxy spring (green).
inline bool surface_pixel(const std::array<int, 4>& p) {
  const double r = p[0], g = p[1], b = p[2];
  return b >= 40 && b - r >= 12 && r >= 0.6 * b && r <= 0.95 * b && g >= 0.75 * b && g <= b;
}

// Of a square window (half size `half_px`, centred on x, y) of two frames: the pixels that show the surface in both,
// and those of them that differ (where the surface moved under the fixed camera). The tool and the proxy spring are
// not the surface: drawn over a surface that did not move, they count nothing.
inline std::pair<int, int> surface_pixels_moved(const Image& a, const Image& b, int x, int y, int half_px) {
  int surface = 0, moved = 0;
  for (int v = std::max(0, y - half_px); v < std::min(a.height, y + half_px); ++v)
    for (int u = std::max(0, x - half_px); u < std::min(a.width, x + half_px); ++u) {
      const std::size_t i = (static_cast<std::size_t>(v) * static_cast<std::size_t>(a.width) + static_cast<std::size_t>(u)) * 4;
      const std::array<int, 4> pa{a.rgba[i], a.rgba[i + 1], a.rgba[i + 2], 255}, pb{b.rgba[i], b.rgba[i + 1], b.rgba[i + 2], 255};
      if (!surface_pixel(pa) || !surface_pixel(pb)) continue;
      ++surface;
      moved += pa != pb;
    }
  return {surface, moved};
}

}  // namespace palpate::test
