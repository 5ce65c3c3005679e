#include "runtime/session/device_factory.h"

#include "core/scene_controls.h"

#include <algorithm>
#include <cmath>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "haptics/devices/browser_device.h"
#include "haptics/devices/plugin_device.h"
#include "haptics/devices/replay_device.h"
#include "haptics/devices/scripted_device.h"
#include "haptics/devices/shm_device.h"

namespace palpate {
namespace {

std::string hexf(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

// The scene a recording was made from: "scene" in the summary.json beside its haptic.csv; empty when there is
// none or it cannot be read (a bare haptic.csv is a valid replay log).
std::string recorded_scene(const std::string& target) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::is_directory(target, ec) ? fs::path(target) : fs::path(target).parent_path();
  const fs::path summary = dir / "summary.json";
  if (!fs::is_regular_file(summary, ec) || fs::file_size(summary, ec) > (1u << 20) || ec) return {};
  std::ifstream in(summary);
  std::stringstream text;
  text << in.rdbuf();
  const auto j = nlohmann::json::parse(text.str(), nullptr, false);
  if (j.is_discarded() || !j.is_object() || !j.contains("scene") || !j["scene"].is_string()) return {};
  return j["scene"].get<std::string>();
}

// The same scene file: one path, or (when either is gone or was named from another folder) one file name.
bool same_scene(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code ea, eb;
  const fs::path ca = fs::weakly_canonical(a, ea), cb = fs::weakly_canonical(b, eb);
  if (!ea && !eb && ca == cb) return true;
  return fs::path(a).filename() == fs::path(b).filename();
}

// "driver:target" from the command line, or the scene's device.driver and device.link when spec is empty: the
// driver's name is turned into a DeviceDriver here, once.
struct DeviceChoice {
  DeviceDriver driver = DeviceDriver::kScripted;
  std::string target;
};

Result<DeviceChoice> device_choice(const Scene& scene, const std::string& spec) {
  if (spec.empty()) return DeviceChoice{scene.device.driver, scene.device.link};
  const auto colon = spec.find(':');
  const std::string name = spec.substr(0, colon);
  const auto driver = from_name<DeviceDriver>(name);
  if (!driver)
    return make_error("device '", name, "': unknown driver (known: scripted, shm:NAME, plugin:PATH, replay:PATH, browser)");
  return DeviceChoice{*driver, colon == std::string::npos ? "" : spec.substr(colon + 1)};
}

}  // namespace

Result<DeviceDriver> device_driver(const Scene& scene, const std::string& spec) {
  auto c = device_choice(scene, spec);
  if (!c) return c.error();
  return c.value().driver;
}

std::string plugin_config(const Scene& scene) {
  std::string c = "scene=" + scene.path + ";hand=" + hexf(scene.hand.mass_kg) + "," + hexf(scene.hand.stiffness_N_per_m) +
                  "," + hexf(scene.hand.damping_Ns_per_m);
  for (const Keyframe& k : scene.trajectory)
    c += ";key=" + hexf(k.t_s) + "," + hexf(k.pos_m.x()) + "," + hexf(k.pos_m.y()) + "," + hexf(k.pos_m.z()) + "," +
         (k.button ? "1" : "0");
  return c;
}

DeviceSpecs device_specs_for(const Scene& scene, DeviceDriver driver) {
  DeviceSpecs specs;
  specs.max_force_N = scene.device.max_force_N;
  specs.max_stiffness_N_per_m = scene.device.max_stiffness_N_per_m;
  specs.workspace_half_m = scene.device.workspace_half_m;
  // the scripted handle is held by the emulated hand: its damping is the hand's
  specs.damping_Ns_per_m = driver == DeviceDriver::kScripted ? scene.hand.damping_Ns_per_m : scene.device.damping_Ns_per_m;
  return specs;
}

Result<std::unique_ptr<Device>> make_device(const Scene& scene, const std::string& spec, BrowserLink* browser) {
  auto choice = device_choice(scene, spec);
  if (!choice) return choice.error();
  const DeviceDriver driver = choice.value().driver;
  const std::string& target = choice.value().target;
  const DeviceSpecs specs = device_specs_for(scene, driver);
  // model-relative keys are resolved where the model is loaded (resolve_relative_keys); never played as zeros
  if (driver == DeviceDriver::kScripted || driver == DeviceDriver::kPlugin)
    for (std::size_t i = 0; i < scene.trajectory.size(); ++i)
      if (needs_model(scene.trajectory[i]))
        return make_error("scene '", scene.path, "': trajectory[", std::to_string(i),
                          "]: pos_rel / surface are resolved against the model, which this command does not load");
  const std::string name = name_of(driver);
  if (driver != DeviceDriver::kScripted && driver != DeviceDriver::kBrowser && target.empty())
    return make_error("device '", name, "': needs a target (", driver == DeviceDriver::kShm ? "shm:NAME" : name + ":PATH",
                      ", or device.link in the scene)");
  switch (driver) {
    case DeviceDriver::kScripted:
      return std::unique_ptr<Device>(std::make_unique<ScriptedDevice>(specs, scene.hand, scene.trajectory));
    case DeviceDriver::kShm: {
      ShmParams p;
      p.name = target;
      p.watchdog_s = scene.device.watchdog_ms * 1e-3;
      p.max_speed_m_per_s = scene.device.max_speed_m_per_s;
      auto d = ShmDevice::connect(p, specs, scene.rates);
      if (!d) return d.error();
      return std::unique_ptr<Device>(std::move(d).value());
    }
    case DeviceDriver::kPlugin: {
      auto d = PluginDevice::load(target, plugin_config(scene), specs);
      if (!d) return d.error();
      return std::unique_ptr<Device>(std::move(d).value());
    }
    case DeviceDriver::kBrowser:
      if (!browser)
        return make_error("device 'browser': the page is the device: it needs the live view (palpate record --serve "
                          "[ADDR:]PORT --mode realtime)");
    {
      auto d = std::make_unique<BrowserDevice>(specs, scene.hand, browser_params(scene), browser, scene.rates);
      d->set_controls(scene_controls(scene));
      return std::unique_ptr<Device>(std::move(d));
    }
    case DeviceDriver::kReplay: {
      auto rows = load_haptic_csv(target);
      if (!rows) return rows.error();
      // the poses were made against another scene's model: allowed (same hand, other object), but said
      const std::string from = recorded_scene(target);
      if (!from.empty() && !same_scene(from, scene.path))
        std::fprintf(stderr, "palpate: warning: replay '%s' was recorded from scene '%s', this run is '%s': the hand "
                     "follows the other scene's poses\n", target.c_str(), from.c_str(), scene.path.c_str());
      // the controls the recording's person changed must be ones this scene allows (a replay against another scene)
      int64_t checked = 0;
      for (const ReplayRow& r : rows.value()) {
        if (r.controls.seq <= checked) continue;
        checked = r.controls.seq;
        if (const std::string why = refuse_controls(scene, r.controls); !why.empty())
          return make_error("replay '", target, "': line ", std::to_string(r.line), ": the controls changed there: ", why);
      }
      // the recorded order of ticks and frames is followed only at the rate its ticks were made at
      const ReplayRow& last = rows.value().back();
      const bool same_rate = last.scheduled && std::abs(last.t_s - scene.rates.tick_time_s(last.tick)) < 1e-6;
      if (last.scheduled && !same_rate)
        std::fprintf(stderr, "palpate: warning: replay '%s' was recorded at another servo rate than this scene's "
                     "%g Hz: replayed by time, not in the order its ticks and frames ran\n", target.c_str(),
                     scene.rates.servo_hz);
      std::optional<RunSchedule> schedule;
      if (same_rate) {
        // the frames the recording skipped, from its summary: a log that names one of them is refused, naming it
        auto sch = replay_schedule(rows.value(), read_skipped_frames(target), target);
        if (!sch) return sch.error();
        schedule = std::move(sch).value();
      }
      return std::unique_ptr<Device>(std::make_unique<ReplayDevice>(specs, std::move(rows).value(), std::move(schedule)));
    }
  }
  return make_error("device '", name, "': unknown driver");
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

}  // namespace palpate
