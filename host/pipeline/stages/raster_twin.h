// Scalar twin of kernels/raster.cl: per-sample coverage and depth, written as a z-buffer loop
// over triangles (independent of the binning the kernel relies on).
#pragma once
#include <cstdint>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {

// Winning slot per sample, index (y * width + x) * sample_count + s; SEAMCL_NO_TRIANGLE if none.
// The winner has the largest 1/w; equal depths go to the lower slot.
std::vector<uint32_t> raster_reference(const std::vector<TriangleSetup>& setups, const FrameParams& frame);

// 1/w of a setup's plane at a pixel-space point.
inline float plane_inv_w(const TriangleSetup& t, float x, float y) {
  return t.inv_w[0] + t.inv_w[1] * (x - t.ref_x) + t.inv_w[2] * (y - t.ref_y);
}

}  // namespace seamcl
