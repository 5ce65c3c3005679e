// Example device plugin: the emulated hand device (haptics/scripted_device) behind the C ABI of
// haptics/shim/palpate_plugin.h. A vendor wrapper has the same shape with the SDK's calls in its place.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "haptics/devices/scripted_device.h"
#include "haptics/shim/palpate_plugin.h"

namespace {

struct Emulated {
  palpate::ScriptedDevice device;
};

// Parses "a,b,c,..." into exactly n numbers.
bool numbers(const std::string& s, double* out, int n) {
  const char* p = s.c_str();
  for (int i = 0; i < n; ++i) {
    char* end = nullptr;
    out[i] = std::strtod(p, &end);
    if (end == p) return false;
    p = end;
    if (i + 1 < n) {
      if (*p != ',') return false;
      ++p;
    }
  }
  return *p == '\0';
}

void* emulated_open(const char* config, char* error, size_t error_size) {
  try {
    palpate::HandSpec hand;
    std::vector<palpate::Keyframe> keys;
    std::string cfg = config ? config : "";
    std::size_t start = 0;
    while (start <= cfg.size()) {
      const std::size_t end = std::min(cfg.find(';', start), cfg.size());
      const std::string item = cfg.substr(start, end - start);
      start = end + 1;
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos) continue;
      const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
      if (key == "hand") {
        double v[3];
        if (!numbers(value, v, 3) || v[0] <= 0.0) {
          std::snprintf(error, error_size, "emulated: bad hand '%s' (mass,stiffness,damping)", value.c_str());
          return nullptr;
        }
        hand = {v[0], v[1], v[2]};
      } else if (key == "key") {
        double v[5];
        if (!numbers(value, v, 5) || (!keys.empty() && !(v[0] > keys.back().t_s))) {
          std::snprintf(error, error_size, "emulated: bad key '%s' (t_s,x,y,z,button, increasing t_s)", value.c_str());
          return nullptr;
        }
        keys.push_back({v[0], palpate::Vec3(v[1], v[2], v[3]), v[4] != 0.0});
      }
    }
    if (keys.empty()) {
      std::snprintf(error, error_size, "emulated: no trajectory (key=t_s,x,y,z,button entries) in the config");
      return nullptr;
    }
    palpate::DeviceSpecs specs;
    return new Emulated{palpate::ScriptedDevice(specs, hand, std::move(keys))};
  } catch (const std::exception& e) {
    std::snprintf(error, error_size, "emulated: %s", e.what());
    return nullptr;
  }
}

int emulated_specs(void* dev, palpate_plugin_specs* out) {
  const palpate::DeviceSpecs& s = static_cast<Emulated*>(dev)->device.specs();
  *out = {s.max_force_N, s.max_stiffness_N_per_m, s.workspace_half_m, s.rate_hz};
  return 1;
}

int emulated_read(void* dev, double t_s, palpate_plugin_pose* out) {
  palpate::DevicePose p;
  if (!static_cast<Emulated*>(dev)->device.read(t_s, &p)) return 0;
  for (int i = 0; i < 3; ++i) out->pos_m[i] = p.pos_m[i];
  out->quat_wxyz[0] = p.orientation.w();
  out->quat_wxyz[1] = p.orientation.x();
  out->quat_wxyz[2] = p.orientation.y();
  out->quat_wxyz[3] = p.orientation.z();
  out->buttons = p.buttons;
  return 1;
}

void emulated_write(void* dev, const double force_N[3]) {
  static_cast<Emulated*>(dev)->device.write_force(palpate::Vec3(force_N[0], force_N[1], force_N[2]));
}

void emulated_close(void* dev) { delete static_cast<Emulated*>(dev); }

const palpate_plugin_api kApi = {PALPATE_PLUGIN_ABI_VERSION, sizeof(palpate_plugin_api), "emulated hand device",
                                 emulated_open, emulated_specs, emulated_read, emulated_write, emulated_close};

}  // namespace

extern "C" __attribute__((visibility("default"))) const palpate_plugin_api* palpate_plugin_entry(void) { return &kApi; }
