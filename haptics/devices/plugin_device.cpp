#include "haptics/devices/plugin_device.h"

#include <dlfcn.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "haptics/force/force_limit.h"

namespace palpate {

PluginDevice::~PluginDevice() {
  if (api_ && dev_) api_->close(dev_);
  if (lib_) dlclose(lib_);
}

Result<std::unique_ptr<PluginDevice>> PluginDevice::load(const std::string& path, const std::string& config,
                                                         const DeviceSpecs& limits) {
  const std::string what = "plugin '" + path + "'";
  std::unique_ptr<PluginDevice> d(new PluginDevice());
  d->lib_ = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!d->lib_) return make_error(what, ": ", dlerror());
  void* sym = dlsym(d->lib_, PALPATE_PLUGIN_ENTRY);
  if (!sym) return make_error(what, ": no symbol '", PALPATE_PLUGIN_ENTRY, "' (not a Palpate device plugin?)");
  palpate_plugin_entry_fn entry = nullptr;
  static_assert(sizeof(entry) == sizeof(sym));
  std::copy_n(reinterpret_cast<const char*>(&sym), sizeof(sym), reinterpret_cast<char*>(&entry));
  const palpate_plugin_api* api = entry();
  if (!api) return make_error(what, ": entry returned no table");
  if (api->abi_version != PALPATE_PLUGIN_ABI_VERSION)
    return make_error(what, ": plugin ABI version ", std::to_string(api->abi_version), ", this build speaks version ",
                      std::to_string(PALPATE_PLUGIN_ABI_VERSION));
  if (api->struct_size != sizeof(palpate_plugin_api) || !api->open || !api->specs || !api->read_pose ||
      !api->write_force || !api->close)
    return make_error(what, ": function table of ", std::to_string(api->struct_size), " bytes or with empty entries (expected ",
                      std::to_string(sizeof(palpate_plugin_api)), ", all set)");
  d->api_ = api;
  d->name_ = api->name ? api->name : "unnamed";
  std::array<char, 512> err{};
  d->dev_ = api->open(config.c_str(), err.data(), err.size());
  err.back() = '\0';
  if (!d->dev_) return make_error(what, ": open failed: ", err[0] ? err.data() : "no message");
  palpate_plugin_specs ps{};
  if (api->specs(d->dev_, &ps) != 1) return make_error(what, ": specs failed");
  const double v[4] = {ps.max_force_N, ps.max_stiffness_N_per_m, ps.workspace_half_m, ps.rate_hz};
  const char* names[4] = {"max_force_N", "max_stiffness_N_per_m", "workspace_half_m", "rate_hz"};
  for (int i = 0; i < 4; ++i)
    if (!std::isfinite(v[i]) || v[i] <= 0.0)
      return make_error(what, ": specs ", names[i], " ", std::to_string(v[i]), " must be finite and > 0");
  d->specs_ = limits;
  d->specs_.max_force_N = std::min(limits.max_force_N, ps.max_force_N);
  d->specs_.max_stiffness_N_per_m = std::min(limits.max_stiffness_N_per_m, ps.max_stiffness_N_per_m);
  d->specs_.workspace_half_m = std::min(limits.workspace_half_m, ps.workspace_half_m);
  return d;
}

bool PluginDevice::read(double t_s, DevicePose* out) noexcept {
  palpate_plugin_pose p{};
  if (api_->read_pose(dev_, t_s, &p) != 1) {
    ++bad_readings_;
    return false;
  }
  const Vec3 pos(p.pos_m[0], p.pos_m[1], p.pos_m[2]);
  Quat q(p.quat_wxyz[0], p.quat_wxyz[1], p.quat_wxyz[2], p.quat_wxyz[3]);
  const double qn = q.norm();
  if (!pos.allFinite() || !std::isfinite(qn) || qn < 0.5 || qn > 2.0) {
    ++bad_readings_;
    return false;
  }
  out->pos_m = pos;
  out->orientation = Quat(q.coeffs() / qn);
  out->buttons = static_cast<uint32_t>(p.buttons & 0xffffffffu);
  return true;
}

void PluginDevice::write_force(const Vec3& force_N) noexcept {
  const Vec3 f = limit_force(force_N, specs_.max_force_N);
  const double a[3] = {f.x(), f.y(), f.z()};
  api_->write_force(dev_, a);
}

}  // namespace palpate
