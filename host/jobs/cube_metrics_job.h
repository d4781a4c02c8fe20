// The cube-metrics job: every cube-map seam method at every cube size, measured against the
// scene's environment function (analytic, or an image loaded from a scene file;
// host/eval/cube_metrics.h): seam step per lod at the 12 edges, first-order jump, error of an
// envmap frame against the environment integrated over each pixel (all pixels and those whose
// footprint crosses a cube edge), time per frame and cube-map memory. What `seamcl cube-metrics`
// runs.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/jobs/job.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// scene, cube_methods, cube_sizes, size, filter, msaa, frame, frames, repeat, reference_scale.
const OptionTable& cube_metrics_option_table();

class CubeMetricsJob {
 public:
  // Parses and checks the request before any work; InputError naming the field.
  explicit CubeMetricsJob(const nlohmann::json& request);

  // The measured frame's options (scene, size, filter, msaa, frame, frames).
  const RenderOptions& frame() const { return frame_; }

  // InputError("scene") for a scene without an environment; else the memory at most: the
  // reference render (reference_scale times the size per axis) or a measured frame, and the
  // largest cube.
  JobPlan plan(const Scene& scene) const;

  // Measures every method at every cube size; with `images_dir` (an existing directory) also
  // writes reference.png, cube_edge_mask.png and METHOD-SIZE.png there. Returns {scene, size,
  // filter, msaa, reference_scale, edge_pixels, device, results: [{cube_size, cube_method, bake,
  // edges_averaged, border, seam_step, seam_step_max, seam_step_half_lod, first_order_jump,
  // environment_first_order_jump, first_order_band, environment_band_slope, ms: {median, min,
  // max}, cube_bytes, bake_ms, error: {mean, p99, max, nan_pixels}, edge_error: {mean, p99, max, pixels,
  // nan_pixels}}]}. Cancelled between entries when control.should_stop says so.
  nlohmann::json run(ClRuntime& runtime, const Scene& scene, const JobControl& control,
                     const std::string& images_dir = "") const;

 private:
  RenderOptions frame_;
  std::vector<CubeMethod> methods_;
  std::vector<int> sizes_;
  int repeat_ = 5;
  int reference_scale_ = 8;
};

}  // namespace seamcl
