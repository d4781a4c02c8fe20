// What every job (render, compare, bench, cube-metrics, displacement-metrics) shares. A job is a
// request parsed from one JSON object (the command line's flags build the same object, the service
// receives it, the Python module builds it from keywords), a plan made before anything is
// allocated, and a run that reports progress, can be cancelled, and returns the documented result
// JSON. Front ends (cli/, server/, python/) adapt a job; none holds a workflow of its own:
//
//   CompareJob job(request);                      // InputError naming the field on bad input
//   const JobPlan plan = job.plan(scene);          // memory by share, nothing allocated
//   refuse_beyond_machine(plan, runtime.info());   // or a server's per-request budget
//   const nlohmann::json result = job.run(runtime, scene, control);
#pragma once
#include <cstddef>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/core/cancelled.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/memory/render_memory.h>

namespace seamcl {

// How a front end watches and steers a running job.
struct JobControl {
  // One line per unit of work ("entry 3/10: traverse at msaa 8"); empty: silent.
  std::function<void(const std::string&)> progress;
  // Asked between units of work (renders, entries, frames); true stops the job with Cancelled.
  // The CLI's Ctrl-C, the service's deadline and gone client, Python's KeyboardInterrupt.
  ShouldStop should_stop;
  // Every Renderer the job makes is held to this many device bytes (0: no bound): a crowded
  // frame's tile lists grow past any plan, and the limit refuses that growth (OverBudget).
  size_t device_byte_limit = 0;

  // The units of work done of the total (a compare's entries), once before the first (0 of the
  // total) and after each; empty: silent. A progress bar's figures, where `progress` gives words.
  std::function<void(int done, int total)> steps;

  void report(const std::string& line) const {
    if (progress) progress(line);
  }
  void step(int done, int total) const {
    if (steps) steps(done, total);
  }
};

// The memory a job will need at most, by share (MemoryShares names the request field that drives
// each): the only estimate a front end refuses a job on, the command line against the machine, the
// service against its per-request budget.
struct JobPlan {
  std::string what;  // "this render", "this compare": the subject of a refusal's sentence
  MemoryShares device, host;
  // The same bytes on a device that shares the host's memory (a CPU): each counted once, at the
  // job's peak (the scene buffers are the packed arrays themselves), with the process overhead.
  // Empty where a job has no such figure: device and host are then counted apart everywhere.
  MemoryShares unified;

  // {"device_bytes", "host_bytes", "total_bytes", "unified", "total_shares"}: the figure the
  // machine is held to on `unified_device` (unified) or elsewhere (device + host).
  nlohmann::json estimate_json(bool unified_device) const;
};

// OverBudget naming the largest share when the plan does not fit this machine: on a device that
// shares the host's memory the unified figure against the physical memory, elsewhere each figure
// against its own memory. For the command line, before any allocation (the service holds a job to
// its per-request budget instead).
void refuse_beyond_machine(const JobPlan& plan, const DeviceInfo& device);

// The request's keys that are not in `known` are refused (InputError naming the first): a key a
// job does not read would otherwise be ignored without a word.
void refuse_unknown_keys(const nlohmann::json& request, const std::vector<std::string>& known);

// "[step/total] ", the head of a job's progress line for one of its steps.
std::string step_of(size_t step, size_t total);

// The strings of a JSON array (a request's list option, already checked against its table).
std::vector<std::string> strings_of(const nlohmann::json& items);

}  // namespace seamcl
