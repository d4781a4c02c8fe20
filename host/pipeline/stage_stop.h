// The stop check a render asks between its stages (packing, the cube map's bake, the kernels, the
// frame), set for the calling thread by whoever runs the render (RenderJob::run, from its
// JobControl) for as long as a StageStopScope lives. A Renderer renders on the caller's thread, so
// the check reaches it without passing through every caller; a scope ends with the run, so no
// Renderer keeps another run's check.
#pragma once
#include <string>
#include <utility>

#include <seamcl/core/cancelled.h>

namespace seamcl {

namespace detail {
inline thread_local const ShouldStop* stage_stop = nullptr;
}  // namespace detail

class StageStopScope {
 public:
  explicit StageStopScope(const ShouldStop& should_stop) : previous_(detail::stage_stop) { detail::stage_stop = &should_stop; }
  ~StageStopScope() { detail::stage_stop = previous_; }
  StageStopScope(const StageStopScope&) = delete;
  StageStopScope& operator=(const StageStopScope&) = delete;

 private:
  const ShouldStop* previous_;
};

// Throws Cancelled("before <stage>") when this thread's render has been asked to stop.
inline void throw_if_stage_stopped(const std::string& stage) {
  if (detail::stage_stop) throw_if_stopped(*detail::stage_stop, "before " + stage);
}

}  // namespace seamcl
