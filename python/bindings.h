#pragma once
/// What the two halves of the compiled module share: its exceptions, the scene it holds, and a run with the GIL
/// released that Ctrl-C stops.

#include <atomic>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "core/scene.h"
#include "haptics/servo/haptic_sample.h"

namespace palpate::python {

/// A scene refused: palpate.SceneError (a ValueError), its message the command line's.
struct SceneFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A run that failed: palpate.RunError (a RuntimeError), its message the command line's.
struct RunFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// haptic.csv's columns as float64 arrays, one row per sample, named as the file's header names them.
pybind11::dict log_arrays(const std::vector<HapticSample>& rows);

/// Runs work(stop) on a thread of its own with the GIL released; the calling thread checks Python's signals every
/// 50 ms and, on one (Ctrl-C), sets stop, waits for work to end and raises what the signal raised
/// (KeyboardInterrupt) after it.
void run_interruptible(const std::function<void(const std::atomic<bool>* stop)>& work);

/// The Session class (bindings_session.cpp).
void bind_session(pybind11::module_& m);

}  // namespace palpate::python
