#include "tools/bench/bench_force.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/scene.h"
#include "runtime/session/device_factory.h"
#include "runtime/session/model.h"
#include "runtime/session/session.h"

namespace palpate {
namespace {

/// Force sent on every servo tick of one lockstep run.
struct ForceTrace {
  std::vector<Vec3> force_N;
  double sim_ms_per_scene_s = 0.0;
};

// Lockstep run with the sim stepping at frame_hz (the scene's, or the servo's for the reference) and the given
// force model, the surface blended over each frame or taken at once.
Result<ForceTrace> run(const Scene& scene_in, const Model& model, double frame_hz, ForceModel fm, bool blend = true) {
  Scene scene = scene_in;
  scene.rates.frame_hz = frame_hz;
  const Rates& rates = scene.rates;
  auto dev = make_device(scene, "scripted");
  if (!dev) return dev.error();
  // the servo `palpate record` runs, with the force model under comparison instead of the scene's
  ServoParams sp = servo_params_for(scene, dev.value()->specs());
  sp.force_model = fm;
  sp.surface_blend = blend;
  Session session(scene, model, dev.value().get(), sp);
  ForceTrace tr;
  tr.force_N.reserve(static_cast<std::size_t>(rates.ticks(scene.duration_s)));
  session.run_lockstep(
      scene.duration_s, [](int64_t, double) {},
      [&](int64_t, double) { tr.force_N.push_back(session.servo().last_sample().force_N); });
  // the stage's own per-frame time (drain, step, deform, publish; there is no rendering here)
  double sim_ms = 0.0;
  for (double ms : session.stage().stats().sim_ms) sim_ms += ms;
  tr.sim_ms_per_scene_s = sim_ms / scene.duration_s;
  return tr;
}

struct ErrorFigures {
  double rms_N = 0.0, max_N = 0.0;
};

ErrorFigures compare(const ForceTrace& a, const ForceTrace& ref) {
  ErrorFigures e;
  double sum = 0.0;
  const std::size_t n = std::min(a.force_N.size(), ref.force_N.size());
  for (std::size_t i = 0; i < n; ++i) {
    const double d = (a.force_N[i] - ref.force_N[i]).norm();
    sum += d * d;
    e.max_N = std::max(e.max_N, d);
  }
  e.rms_N = n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
  return e;
}

const char* model_name(ForceModel m) {
  switch (m) {
    case ForceModel::kHoldFrame: return "hold_last_force";
    case ForceModel::kStaticSurface: return "static_surface";
    case ForceModel::kLocalModel: return "local_model";
  }
  return "?";
}

}  // namespace

int run_bench_force(const BenchForceOptions& o) {
  if (!o.json_path.empty())
    if (auto st = check_output_target(o.json_path, "bench json"); !st) {
      std::fprintf(stderr, "palpate: bench force: %s\n", st.error().message.c_str());
      return 1;
    }
  nlohmann::json out;
  out["reference"] = "lattice stepped at the servo rate, surface published every servo tick";
  out["scenes"] = nlohmann::json::array();
  std::printf("%-22s %-16s %10s %10s %14s\n", "scene", "force_model", "rms_N", "max_N", "sim_ms/scene_s");
  for (const std::string& path : o.scenes) {
    auto scene = load_scene(path);
    if (!scene) {
      std::fprintf(stderr, "palpate: %s\n", scene.error().message.c_str());
      return 1;
    }
    auto model = load_model(scene.value());
    if (!model) {
      std::fprintf(stderr, "palpate: %s\n", model.error().message.c_str());
      return 1;
    }
    auto ref = run(scene.value(), model.value(), scene.value().rates.servo_hz, ForceModel::kStaticSurface);
    if (!ref) {
      std::fprintf(stderr, "palpate: %s\n", ref.error().message.c_str());
      return 1;
    }
    nlohmann::json js{{"scene", path}, {"reference_sim_ms_per_scene_s", ref.value().sim_ms_per_scene_s}};
    std::printf("%-22s %-16s %10s %10s %14.1f\n", scene.value().name.c_str(), "reference_1kHz", "-", "-",
                ref.value().sim_ms_per_scene_s);
    for (ForceModel fm : {ForceModel::kHoldFrame, ForceModel::kStaticSurface, ForceModel::kLocalModel}) {
      auto tr = run(scene.value(), model.value(), scene.value().rates.frame_hz, fm);
      if (!tr) {
        std::fprintf(stderr, "palpate: %s\n", tr.error().message.c_str());
        return 1;
      }
      const ErrorFigures e = compare(tr.value(), ref.value());
      std::printf("%-22s %-16s %10.4f %10.4f %14.1f\n", scene.value().name.c_str(), model_name(fm), e.rms_N, e.max_N,
                  tr.value().sim_ms_per_scene_s);
      js[model_name(fm)] = {{"rms_N", e.rms_N}, {"max_N", e.max_N}, {"sim_ms_per_scene_s", tr.value().sim_ms_per_scene_s}};
    }
    // the local model with each frame's surface taken at its first tick instead of blended over the frame: what the
    // blend's delay of the lattice's deformation costs (or saves) against the reference
    auto nb = run(scene.value(), model.value(), scene.value().rates.frame_hz, ForceModel::kLocalModel, false);
    if (!nb) {
      std::fprintf(stderr, "palpate: %s\n", nb.error().message.c_str());
      return 1;
    }
    const ErrorFigures e = compare(nb.value(), ref.value());
    std::printf("%-22s %-16s %10.4f %10.4f %14.1f\n", scene.value().name.c_str(), "local_no_blend", e.rms_N, e.max_N,
                nb.value().sim_ms_per_scene_s);
    js["local_model_no_blend"] = {{"rms_N", e.rms_N}, {"max_N", e.max_N},
                                  {"sim_ms_per_scene_s", nb.value().sim_ms_per_scene_s}};
    out["scenes"].push_back(js);
  }
  if (!o.json_path.empty()) {
    if (auto st = write_file_atomic(o.json_path, out.dump(2) + "\n", "bench json"); !st) {
      std::fprintf(stderr, "palpate: bench force: %s\n", st.error().message.c_str());
      return 1;
    }
  }
  return 0;
}

}  // namespace palpate
