// The displacement-metrics job: every displacement method at every tessellation level, measured on
// one scene (host/eval/displacement_metrics.h): the exact gap between vertices two patches share,
// crack pixels over an orbit (closed meshes: back faces drawn as a flag, seen only through cracks), time
// per frame and the extra data each method keeps. What `seamcl displacement-metrics` runs; its
// JSON is examples/displacement_chart.py's input.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/jobs/job.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// scene, methods, tessellation (a list), level, size, msaa, frames (0: the scene's camera only),
// repeat.
const OptionTable& displacement_metrics_option_table();

class DisplacementMetricsJob {
 public:
  // Parses and checks the request before any work; InputError naming the field.
  explicit DisplacementMetricsJob(const nlohmann::json& request);

  // The measured frame's options (scene, size, msaa, displacement_level, the first method).
  const RenderOptions& frame() const { return frame_; }

  // InputError for a scene the run cannot measure ("scene" without displacement maps, "frames"
  // without an orbit, "tessellation" past the triangle bound); else the memory at most: a render
  // at the highest level, or of a closed mesh's crack renders (its micro-quads twice) if larger.
  JobPlan plan(const Scene& scene) const;

  // Measures every method at every level (the scene's displacement maps attached by the caller
  // where they come from a file); with `images_dir` (an existing directory) also writes frame 0
  // of each entry there as METHOD_TT.png (cracks magenta), its path in the entry's "image".
  // Returns {scene, size, msaa, level, crack_frames, closed_mesh, repeat, device, results:
  // [DisplacementReport::to_json()]}. Cancelled between entries when control.should_stop says so.
  nlohmann::json run(ClRuntime& runtime, const Scene& scene, const JobControl& control,
                     const std::string& images_dir = "") const;

 private:
  RenderOptions frame_;
  std::vector<DisplacementMethod> methods_;
  std::vector<int> levels_;
  int frames_ = 60;
  int repeat_ = 5;
};

}  // namespace seamcl
