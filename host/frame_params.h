// The per-frame constants of the pipeline (FrameParams): camera matrices, clip planes sized so
// that fixed-point arithmetic cannot overflow, tiles, samples and lighting.
#pragma once
#include <cstdint>

#include "gpu_types.h"
#include "render_options.h"
#include "scene.h"

namespace seamcl {

inline constexpr float kNearPlane = 0.01f;
// Snapped screen coordinates stay within +-2^20 pixels: with 8 sub-pixel bits the edge-function
// products then stay below 2^58, inside a 64-bit integer.
inline constexpr double kMaxScreenCoordinate = 1 << 20;

glm::mat4 view_projection(const Camera& camera, int width, int height);

FrameParams make_frame_params(const Scene& scene, const Camera& camera, const RenderOptions& options,
                              uint32_t bin_capacity);

}  // namespace seamcl
