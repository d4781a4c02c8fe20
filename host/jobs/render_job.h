// The render job: one frame of a scene, rendered `repeat` times (the median time per stage
// reported, the last image kept); what `seamcl render`, GET/POST /v1/render and seamcl.render()
// run.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/jobs/job.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {

// The render request's options: every render option, and the job's own: repeat, crack_orbit,
// export_mesh (the command line's: the HTTP service refuses them).
const OptionTable& render_job_option_table();

struct RenderRun {
  RenderResult last;                // the last render's image and counts
  std::vector<StageTimes> times;    // one per render
  StageTimes median;                // per stage, over `times`
  nlohmann::json displacement;      // a displaced frame's gap and crack pixels, when asked for
};

class RenderJob {
 public:
  // Parses and checks the request; InputError naming the field.
  explicit RenderJob(const nlohmann::json& request);

  const RenderOptions& options() const { return options_; }
  int repeat() const { return repeat_; }
  // How the scene is made for this render (tint); textures deferred, baked face by face while packing.
  GeneratorOptions generator_options() const;
  Camera camera(const Scene& scene) const;

  // The most memory the render needs: the Renderer's (render_memory) plus, on the host,
  // `held_scene_bytes` that the request holds besides (its own copy of an inline scene or an asset;
  // 0 for a scene the caller keeps anyway).
  JobPlan plan(const Scene& scene, size_t held_scene_bytes = 0) const;

  // Renders with `renderer`, which has `scene` loaded: a warm-up (the kernels built, untimed),
  // then `repeat` timed renders. With `measure_watertightness` and a displaced frame, the gap and
  // crack pixels too (over crack_orbit frames of the orbit when given). With export_mesh, the
  // frame's tessellated patches are written there last (host/io/mesh_export.h). Cancelled between
  // renders when control.should_stop says so.
  RenderRun run(ClRuntime& runtime, Renderer& renderer, const Scene& scene, const JobControl& control,
                bool measure_watertightness = false) const;

  // {"device", "options", "ms": {total, setup, binning, raster, shade, readback}, "runs",
  //  "triangles", "visible_triangles", "fragments", "texture_bytes", "padding_bytes",
  //  "adjacency_bytes", "bin_entries", "displacement" (when measured)}.
  nlohmann::json result_json(const RenderRun& run, const Renderer& renderer, const std::string& device) const;
  // The stage times of one set: {setup, binning, raster, shade, readback, total}.
  static nlohmann::json stage_ms_json(const StageTimes& times);

 private:
  RenderOptions options_;
  int repeat_ = 1;
  int crack_orbit_ = 0;
  std::string export_mesh_;  // empty: no export
};

}  // namespace seamcl
