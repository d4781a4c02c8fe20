// What every job (render, compare, bench, cube-metrics, displacement-metrics) shares. A job is a
// request parsed from one JSON object (the command line's flags build the same object, the service
// receives it, the Python module builds it from keywords), a plan made before anything is
// allocated, and a run that reports progress, can be cancelled, and returns the documented result
// JSON. Front ends (cli/, server/, python/) adapt a job; none holds a workflow of its own:
//
//   CompareJob job(request);                      // InputError naming the field on bad input
//   const JobPlan plan = job.plan(scene);          // memory by share, nothing allocated
//   refuse_beyond_machine(plan.device, plan.host, device, plan.what);   // or a server's budget
//   const nlohmann::json result = job.run(runtime, scene, control);
#pragma once
#include <cstddef>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/core/cancelled.h>
#include <seamcl/pipeline/render_memory.h>

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

  void report(const std::string& line) const {
    if (progress) progress(line);
  }
};

// The memory a job will need at most, by share (MemoryShares names the request field that drives
// each): the only estimate a front end refuses a job on, the command line against the machine, the
// service against its per-request budget.
struct JobPlan {
  std::string what;  // "this render", "this compare": the subject of a refusal's sentence
  MemoryShares device, host;

  // {"what", "device_bytes", "host_bytes", "device_shares": {field: bytes}, "host_shares": {...}}
  nlohmann::json to_json() const;
};

// The request's keys that are not in `known` are refused (InputError naming the first): a key a
// job does not read would otherwise be ignored without a word.
void refuse_unknown_keys(const nlohmann::json& request, const std::vector<std::string>& known);

}  // namespace seamcl
