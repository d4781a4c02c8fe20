// The pixel inspector's launcher (kernels/shade_inspect.cl, in the shading program built with
// SEAMCL_INSPECT): the per-sample records of a small window of the last frame, from the buffers
// that frame's shading read.
#pragma once
#include <string>
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/gpu_types.h>
#include "pipeline/stages/shade_resolve_launcher.h"

namespace seamcl {

// A window of pixels in the image: [x, x + width) x [y, y + height).
struct PixelWindow {
  int x = 0, y = 0, width = 1, height = 1;
};

class ShadeInspectLauncher {
 public:
  explicit ShadeInspectLauncher(ClRuntime& runtime) : runtime_(runtime) {}

  // Runs the kernel of the shading program built with `shading_options` plus SEAMCL_INSPECT on
  // the window (inside p's image; the caller checks) and reads the records back, sample_count per
  // pixel, pixel-major. `adjacency`: the scene buffers hold the faces' neighbours.
  std::vector<InspectSample> inspect(const std::string& shading_options, const cl::Buffer& frame_params,
                                     const cl::Buffer& setups, const ShadeSceneBuffers& scene,
                                     const cl::Buffer& sample_triangle, const FrameParams& p, bool adjacency,
                                     const PixelWindow& window);

 private:
  ClRuntime& runtime_;
};

}  // namespace seamcl
