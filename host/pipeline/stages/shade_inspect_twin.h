// Scalar twin of kernels/shade_inspect.cl: the pixel inspector's per-sample records (which
// fragment colours each sample, where it is shaded, and its texture lookup taken apart).
#pragma once
#include <cstdint>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/pipeline/packed_scene.h>
#include "pipeline/stages/shade_resolve_twin.h"

namespace seamcl {

// The records of the window's pixels, pixel-major (row-major within the window), sample_count
// each, from the frame's setups and sample winners: what the kernel writes for the same window.
// `cube_texels`: the renderer's Renderer::cube_texels() (scenes with an environment only).
// `displaced`: a displaced render lit by its surface's normals, as shade_resolve_reference takes it.
std::vector<InspectSample> shade_inspect_reference(const PackedScene& scene, const FrameParams& frame,
                                                   const std::vector<TriangleSetup>& setups,
                                                   const std::vector<uint32_t>& sample_triangle, int window_x,
                                                   int window_y, int window_width, int window_height,
                                                   const std::vector<float>* cube_texels = nullptr,
                                                   const DisplacedShadingReference* displaced = nullptr);

}  // namespace seamcl
