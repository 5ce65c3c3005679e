// The compiled part of the Python module palpate (python/palpate/ is the rest): scenes parsed and checked by the
// code the command line uses, recordings run with the GIL released and stopped whole by Ctrl-C, the haptic log
// handed over as numpy arrays from memory, and the benchmarks' figures as JSON.
#include "python/bindings.h"

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <mutex>
#include <sstream>
#include <thread>

#include <pybind11/stl.h>

#include "core/input_file.h"
#include "core/limits.h"
#include "runtime/record/record_plan.h"
#include "runtime/record/recorder.h"
#include "runtime/session/haptic_log.h"
#include "runtime/session/model.h"
#include "tools/bench/bench_feel.h"
#include "tools/bench/bench_model.h"

namespace py = pybind11;

namespace palpate::python {

py::dict log_arrays(const std::vector<HapticSample>& rows) {
  py::dict out;
  std::vector<std::string> names;
  std::stringstream header(kHapticLogColumns);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  const auto n = static_cast<py::ssize_t>(rows.size());
  std::vector<py::array_t<double>> cols;
  for (std::size_t c = 0; c < names.size(); ++c) cols.emplace_back(n);
  std::vector<double*> col_data;
  for (auto& a : cols) col_data.push_back(a.mutable_data());
  double values[kHapticLogWidth];
  for (py::ssize_t i = 0; i < n; ++i) {
    haptic_log_values(rows[static_cast<std::size_t>(i)], values);
    for (std::size_t c = 0; c < names.size(); ++c) col_data[c][i] = values[c];
  }
  for (std::size_t c = 0; c < names.size(); ++c) out[py::str(names[c])] = cols[c];
  return out;
}

void run_interruptible(const std::function<void(const std::atomic<bool>* stop)>& work) {
  std::atomic<bool> stop{false};
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  std::exception_ptr failure;
  std::thread worker([&] {
    try {
      work(&stop);
    } catch (...) {
      failure = std::current_exception();
    }
    const std::lock_guard<std::mutex> lock(m);
    done = true;
    cv.notify_all();
  });
  bool interrupted = false;
  PyObject *type = nullptr, *value = nullptr, *trace = nullptr;
  for (;;) {
    {
      const py::gil_scoped_release nogil;
      std::unique_lock<std::mutex> lock(m);
      if (cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
    }
    if (!interrupted && PyErr_CheckSignals() != 0) {
      // keep what the signal raised, let the work end whole, then raise it
      PyErr_Fetch(&type, &value, &trace);
      interrupted = true;
      stop.store(true);
    }
  }
  {
    const py::gil_scoped_release nogil;
    worker.join();
  }
  if (interrupted) {
    PyErr_Restore(type, value, trace);
    throw py::error_already_set();
  }
  if (failure) std::rethrow_exception(failure);
}

namespace {

Scene parse(const std::string& text, const std::string& path) {
  auto scene = parse_scene(text, path);
  if (!scene) throw SceneFailure(scene.error().message);
  return std::move(scene).value();
}

std::string read_scene_text(const std::string& path) {
  auto text = read_input_file(path, "scene", kMaxSceneFileBytes);
  if (!text) throw SceneFailure(text.error().message);
  return std::move(text).value();
}

// One recording as `palpate record` makes it; the rows of haptic.csv kept in memory as they are logged.
py::dict record(const Scene& scene_in, const std::string& out_dir, const std::string& mode, bool frames, bool video,
                double duration_s, const std::string& device, bool quiet) {
  Scene scene = scene_in;
  RecordOptions opt;
  opt.out_dir = out_dir;
  opt.quiet = quiet;
  opt.render = frames;
  opt.video_optional = frames && video;
  opt.duration_s = duration_s;
  opt.device = device;
  opt.lock_memory = false;  // mlockall would stay on the interpreter's whole process after the run
  if (!mode.empty()) {
    const auto m = from_name<RunMode>(mode);
    if (!m) throw SceneFailure("mode '" + mode + "': use 'lockstep' or 'realtime'");
    opt.override_mode = true;
    opt.mode = *m;
  }
  auto planned = plan_record(scene, opt);
  if (!planned) throw RunFailure(planned.error().message);
  const RecordPlan plan = std::move(planned).value();
  if (auto st = check_plan_outputs(plan); !st) throw RunFailure(st.error().message);
  if (plan.driver == DeviceDriver::kBrowser)
    throw RunFailure("device 'browser': the live page is the device; record it with `palpate record --serve`");
  std::vector<HapticSample> rows;
  opt.samples = &rows;
  Result<RecordResult> res = Error{};
  run_interruptible([&](const std::atomic<bool>* stop) {
    RecordOptions o = opt;
    o.stop = stop;
    res = record_planned(plan, o);
  });
  if (!res) throw RunFailure(res.error().message);
  const RecordResult& r = res.value();
  py::dict out;
  out["summary_json"] = r.summary_json;
  out["summary_path"] = r.summary_path;
  out["log"] = log_arrays(rows);
  out["warnings"] = plan.warnings;
  out["state_hash"] = r.state_hash;
  out["frames_written"] = r.frames_written;
  out["video_path"] = r.video_path;
  out["haptic_csv"] = plan.haptic_csv_path;
  out["frames_dir"] = plan.render ? plan.frames_dir : std::string();
  out["out_dir"] = plan.out_dir;
  out["interrupted"] = r.interrupted;
  out["diverged"] = r.nan_events + r.divergence_events;
  return out;
}

std::string bench_feel(const Scene& scene, const std::string& device, double duration_s) {
  auto model = load_model(scene);
  if (!model) throw RunFailure(model.error().message);
  BenchFeelOptions o;
  o.device = device.empty() ? "scripted" : device;
  o.duration_s = duration_s;
  Result<FeelRun> run = Error{};
  run_interruptible([&](const std::atomic<bool>*) { run = run_feel(scene, model.value(), o); });
  if (!run) throw RunFailure(run.error().message);
  return feel_run_json(run.value()).dump();
}

// bench model's rows (its JSON), for the references and levels asked
void bench_model(const std::vector<std::string>& references, const std::vector<int>& levels, double young_Pa,
                 const std::string& json_path) {
  BenchModelOptions o;
  o.references = references;
  o.levels = levels;
  o.young_modulus_Pa = young_Pa;
  o.json_path = json_path;
  Result<std::string> table = Error{};
  run_interruptible([&](const std::atomic<bool>*) { table = run_bench_model(o); });
  if (!table) throw RunFailure(table.error().message);
}

}  // namespace
}  // namespace palpate::python

PYBIND11_MODULE(_palpate, m) {
  using namespace palpate;
  using namespace palpate::python;
  m.doc() = "Palpate's compiled core; use the package `palpate`";
  py::register_exception<SceneFailure>(m, "SceneError", PyExc_ValueError);
  py::register_exception<RunFailure>(m, "RunError", PyExc_RuntimeError);
  m.attr("haptic_log_columns") = std::string(kHapticLogColumns);

  py::class_<Scene>(m, "NativeScene", "A scene as the command line holds it, checked")
      .def_readonly("name", &Scene::name)
      .def_readonly("path", &Scene::path)
      .def_readonly("duration_s", &Scene::duration_s)
      .def_readonly("warnings", &Scene::warnings)
      .def_property_readonly("mode", [](const Scene& s) { return std::string(mode_name(s.mode)); })
      .def_property_readonly("servo_hz", [](const Scene& s) { return s.rates.servo_hz; })
      .def_property_readonly("frame_hz", [](const Scene& s) { return s.rates.frame_hz; });
  m.def("parse_scene", &parse, py::arg("text"), py::arg("path"),
        "The scene in JSON text; path names it in messages and anchors a relative mesh.file");
  m.def("read_scene_text", &read_scene_text, py::arg("path"), "A scene file's text, read with the CLI's limits");
  m.def("record", &record, py::arg("scene"), py::arg("out_dir"), py::arg("mode") = "", py::arg("frames") = false,
        py::arg("video") = false, py::arg("duration_s") = 0.0, py::arg("device") = "", py::arg("quiet") = true);
  m.def("bench_feel", &bench_feel, py::arg("scene"), py::arg("device") = "", py::arg("duration_s") = 0.0);
  m.def("bench_model", &bench_model, py::arg("references"), py::arg("levels"), py::arg("young_modulus_Pa"),
        py::arg("json_path"));
  bind_session(m);
}
