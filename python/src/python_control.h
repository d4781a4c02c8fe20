// A job's JobControl for a call from Python, made while the call holds the GIL and used while it
// does not (the job runs with the GIL released, so other threads run Python and other renders):
// - progress lines go to a Python callable, the GIL taken for each;
// - should_stop takes the GIL and runs Python's pending signal handlers, so Ctrl-C (SIGINT's
//   KeyboardInterrupt) stops the job at its next unit of work, as the CLI's Ctrl-C does; an
//   exception the progress callable raised stops it too;
// - rethrow_python_error, after the job ended (Cancelled) and with the GIL held again, raises that
//   Python exception rather than Cancelled.
#pragma once
#include <memory>
#include <optional>

#include <nanobind/nanobind.h>

#include <seamcl/jobs/job.h>

namespace seamcl::python {

class PythonControl {
 public:
  // `progress`: a callable taking one str, or None.
  explicit PythonControl(nanobind::object progress);
  ~PythonControl();
  PythonControl(const PythonControl&) = delete;
  PythonControl& operator=(const PythonControl&) = delete;

  // The hooks; valid while this object lives.
  JobControl control() const;
  // Raises the Python exception that stopped the job, if one did (GIL held).
  void rethrow_python_error();

 private:
  struct State;
  std::shared_ptr<State> state_;
};

}  // namespace seamcl::python
