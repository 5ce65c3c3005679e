#include "tools/session/device_factory.h"

#include <algorithm>

#include <cstdio>
#include <filesystem>

#include "core/atomic_file.h"
#include "haptics/plugin_device.h"
#include "haptics/replay_device.h"
#include "haptics/scripted_device.h"
#include "haptics/shm_device.h"

namespace palpate {
namespace {

std::string hexf(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

// Splits "driver:target" (the scene's driver and device.link when spec is empty).
void split_spec(const Scene& scene, const std::string& spec, std::string* driver, std::string* target) {
  if (spec.empty()) {
    *driver = scene.device.driver;
    *target = scene.device.link;
    return;
  }
  const auto colon = spec.find(':');
  *driver = spec.substr(0, colon);
  *target = colon == std::string::npos ? "" : spec.substr(colon + 1);
}

}  // namespace

std::string device_driver(const Scene& scene, const std::string& spec) {
  std::string driver, target;
  split_spec(scene, spec, &driver, &target);
  return driver;
}

std::string plugin_config(const Scene& scene) {
  std::string c = "scene=" + scene.path + ";hand=" + hexf(scene.hand.mass_kg) + "," + hexf(scene.hand.stiffness_N_per_m) +
                  "," + hexf(scene.hand.damping_Ns_per_m);
  for (const Keyframe& k : scene.trajectory)
    c += ";key=" + hexf(k.t_s) + "," + hexf(k.pos_m.x()) + "," + hexf(k.pos_m.y()) + "," + hexf(k.pos_m.z()) + "," +
         (k.button ? "1" : "0");
  return c;
}

Result<std::unique_ptr<Device>> make_device(const Scene& scene, const std::string& spec, double rate_hz) {
  std::string driver, target;
  split_spec(scene, spec, &driver, &target);
  DeviceSpecs specs;
  specs.max_force_N = scene.device.max_force_N;
  specs.max_stiffness_N_per_m = scene.device.max_stiffness_N_per_m;
  specs.workspace_half_m = scene.device.workspace_half_m;
  specs.rate_hz = rate_hz;
  // model-relative keys are resolved where the model is loaded (resolve_relative_keys); never played as zeros
  if (driver == "scripted" || driver == "plugin")
    for (std::size_t i = 0; i < scene.trajectory.size(); ++i)
      if (needs_model(scene.trajectory[i]))
        return make_error("scene '", scene.path, "': trajectory[", std::to_string(i),
                          "]: pos_rel / surface are resolved against the model, which this command does not load");
  if (driver == "scripted") {
    return std::unique_ptr<Device>(std::make_unique<ScriptedDevice>(specs, scene.hand, scene.trajectory));
  }
  if (driver == "shm" || driver == "plugin" || driver == "replay") {
    if (target.empty())
      return make_error("device '", driver, "': needs a target (", driver == "shm" ? "shm:NAME" : driver + ":PATH",
                        ", or device.link in the scene)");
  }
  if (driver == "shm") {
    ShmParams p;
    p.name = target;
    p.watchdog_s = scene.device.watchdog_ms * 1e-3;
    p.max_speed_m_per_s = scene.device.max_speed_m_per_s;
    p.servo_rate_hz = rate_hz;
    auto d = ShmDevice::connect(p, specs);
    if (!d) return d.error();
    return std::unique_ptr<Device>(std::move(d).value());
  }
  if (driver == "plugin") {
    auto d = PluginDevice::load(target, plugin_config(scene), specs);
    if (!d) return d.error();
    return std::unique_ptr<Device>(std::move(d).value());
  }
  if (driver == "replay") {
    auto rows = load_haptic_csv(target);
    if (!rows) return rows.error();
    return std::unique_ptr<Device>(std::make_unique<ReplayDevice>(specs, std::move(rows).value()));
  }
  return make_error("device '", driver, "': unknown driver (known: scripted, shm:NAME, plugin:PATH, replay:PATH)");
}

Status write_device_events(const Device& device, const std::string& out_dir, bool quiet) {
  const DeviceEventLog* events = device.link_events();
  if (events == nullptr) return Ok{};
  const std::string path = (std::filesystem::path(out_dir) / "device_events.csv").string();
  auto out = AtomicFile::open(path, "events", ".partial");
  if (!out) return out.error();
  AtomicFile& f = out.value();
  f.write("tick,t_s,event,silent_ms\n");
  for (int i = 0; i < events->count(); ++i) {
    const DeviceEvent& e = events->at(i);
    char line[128];
    std::snprintf(line, sizeof line, "%lld,%.6f,%s,%.3f\n", static_cast<long long>(e.tick), e.t_s,
                  device_event_name(e.kind), e.silent_ms);
    f.write(line);
    if (!quiet && e.kind != DeviceEventKind::kConnected)
      std::fprintf(stderr, "palpate: device '%s': %s at tick %lld (t = %.3f s, peer silent %.1f ms)\n",
                   device.link_name().c_str(), device_event_name(e.kind), static_cast<long long>(e.tick), e.t_s,
                   e.silent_ms);
  }
  return f.commit();
}

ServoParams servo_params_for(const Scene& scene, const DeviceSpecs& device, double rate_hz) {
  ServoParams sp;
  sp.mode = scene.mode;
  // the coupling never renders more stiffness than the device can display stably, by the scene's word or its own
  sp.coupling_N_per_m = std::min({scene.device.coupling_N_per_m, scene.device.max_stiffness_N_per_m,
                                  device.max_stiffness_N_per_m});
  sp.coupling_damping_Ns_per_m = scene.device.coupling_damping_Ns_per_m;
  sp.passivity = scene.device.passivity;
  sp.ramp_s = scene.device.ramp_s;
  sp.grab_radius_m = scene.grab_radius_m;
  sp.blade_length_m = scene.blade_length_m;
  sp.cut_resistance_Ns_per_m = scene.cut_resistance_Ns_per_m;
  sp.tool_radius_m = scene.device.sphere_tool ? scene.device.tool_radius_m : 0.0;
  sp.period_s = 1.0 / rate_hz;
  return sp;
}

}  // namespace palpate
