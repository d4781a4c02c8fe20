// The inspect job: what made a pixel. Renders the frame of a render request, then runs the
// shading stage's debug variant (kernels/shade_inspect.cl) on a small window of it and answers
// per pixel and sample: the triangle, face, coverage, shading point, uv, mip levels, footprint
// axes and probe count, and the faces the lookup's taps came from with their weights. What POST
// /v1/inspect and the viewer's pixel inspector run.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/jobs/job.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// The inspect request's own options (x, y, window); the rest of a request is a render request.
const OptionTable& inspect_job_option_table();

class InspectJob {
 public:
  // Parses and checks the request; InputError naming the field (x and y are required; the
  // window inside the image is checked when the frame is made).
  explicit InspectJob(const nlohmann::json& request);

  const RenderJob& render_job() const { return render_; }
  const RenderOptions& options() const { return render_.options(); }
  int x() const { return x_; }
  int y() const { return y_; }
  // The window's side: window x window pixels from (x, y), cut at the image's right and bottom.
  int window() const { return window_; }

  // The render's plan: the records of a window are a few KiB.
  JobPlan plan(const Scene& scene, size_t held_scene_bytes = 0) const { return render_.plan(scene, held_scene_bytes); }

  // Renders the frame with `renderer` (which has `scene` loaded) and inspects the window:
  // {"x", "y", "width", "height", "options", "samples", "shading", "method", "filter", "renormalize",
  //  "pixels": [{"x", "y", "color", "fragments", "samples": [record...]}]} (docs/service.md).
  nlohmann::json run(Renderer& renderer, const Scene& scene, const JobControl& control) const;

  // One record as its JSON (the "samples" items above); `renormalize`: the method divides by the
  // summed weight, so each tap's share is its weight over that sum.
  static nlohmann::json sample_json(int sample, const InspectSample& record, bool renormalize);

 private:
  RenderJob render_;
  int x_ = 0, y_ = 0, window_ = 1;
};

}  // namespace seamcl
