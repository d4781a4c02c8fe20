// The raster stage's launcher (kernels/raster.cl): one work-item per tile walks the tile's list
// and writes, per sample, the slot of the nearest covering triangle into a buffer it keeps for
// shading to read.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/gpu_types.h>
#include "pipeline/stages/binning_launcher.h"

namespace seamcl {

class RasterLauncher {
 public:
  explicit RasterLauncher(ClRuntime& runtime) : runtime_(runtime) {}

  // Sizes the per-sample slots for the frame's pixels and samples.
  void reserve(const FrameParams& p);
  // Queues raster of the frame's tiles from the setup records and binning's lists; its event is
  // appended.
  void enqueue(const cl::Buffer& frame_params, const cl::Buffer& setups, const BinningLauncher& binning,
               const FrameParams& p, std::vector<cl::Event>& events);

  const cl::Buffer& sample_triangle() const { return sample_triangle_; }

  // The last frame's slot per sample (p's pixels and samples), in input order.
  std::vector<uint32_t> read_sample_triangles(const FrameParams& p);

  void release();
  size_t device_bytes() const;

 private:
  ClRuntime& runtime_;
  cl::Kernel& kernel();  // built on first use: the geometry program has no variants
  cl::Kernel kernel_;
  cl::Buffer sample_triangle_;
  size_t samples_capacity_ = 0;
};

}  // namespace seamcl
