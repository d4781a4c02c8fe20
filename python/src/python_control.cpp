#include "python_control.h"

#include <atomic>
#include <utility>

namespace nb = nanobind;

namespace seamcl::python {

struct PythonControl::State {
  nb::object progress;
  // The exception that asked the job to stop (KeyboardInterrupt, or the progress callable's); set
  // and read with the GIL held, `stopped` read without it.
  std::optional<nb::python_error> error;
  std::atomic<bool> stopped{false};

  // With the GIL held, after a Python call failed: keep its exception, stop the job.
  void keep_error() {
    if (!error) error.emplace();
    else PyErr_Clear();
    stopped = true;
  }
};

PythonControl::PythonControl(nb::object progress) : state_(std::make_shared<State>()) {
  state_->progress = std::move(progress);
}

PythonControl::~PythonControl() = default;

JobControl PythonControl::control() const {
  JobControl control;
  State* state = state_.get();
  if (!state->progress.is_none()) {
    control.progress = [state](const std::string& line) {
      if (state->stopped) return;
      nb::gil_scoped_acquire gil;
      PyObject* result = PyObject_CallOneArg(state->progress.ptr(), nb::str(line.c_str(), line.size()).ptr());
      if (result) Py_DECREF(result);
      else state->keep_error();
    };
  }
  control.should_stop = [state]() {
    if (state->stopped) return true;
    nb::gil_scoped_acquire gil;
    // Runs the handlers of signals caught since (main thread only, as Python does): SIGINT's
    // default one raises KeyboardInterrupt.
    if (PyErr_CheckSignals() != 0) state->keep_error();
    return state->stopped.load();
  };
  return control;
}

void PythonControl::rethrow_python_error() {
  if (state_->error) {
    nb::python_error error = std::move(*state_->error);
    state_->error.reset();
    throw error;
  }
}

}  // namespace seamcl::python
