// The launcher of kernels/ptex_filter.cl: uploads a PtexFilterData once and runs batches of
// lookups of Ptex's own filters on the device.
#pragma once
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include "pipeline/stages/ptex_filter_twin.h"

namespace seamcl {

class PtexFilterLauncher {
 public:
  explicit PtexFilterLauncher(ClRuntime& runtime);

  // Uploads faces, level offsets and texels.
  void load(const PtexFilterData& data);

  // 4 floats per query (channels beyond the texture's are 0), in order. A batch of point lookups
  // alone runs through a kernel of its own (ptex_point_lookups), shorter per lookup.
  std::vector<float> run(const std::vector<PtexFilterQuery>& queries);

  // Uploads `queries` once (for timing) and runs them `repeats` times back to back; returns the
  // kernel milliseconds of each run (OpenCL profiling events).
  std::vector<double> time(const std::vector<PtexFilterQuery>& queries, int repeats);

  size_t device_bytes() const { return device_bytes_; }

 private:
  // The kernel for `queries` (ptex_point_lookups when every one is a point lookup), its arguments
  // set to the texture, `in` and `out`.
  cl::Kernel& kernel_with_args(const std::vector<PtexFilterQuery>& queries, const cl::Buffer& in,
                               const cl::Buffer& out);

  ClRuntime& runtime_;
  cl::Kernel kernel_;
  cl::Kernel point_kernel_;
  PtexFilterTexture texture_{};
  cl::Buffer faces_, level_offsets_, texels_;
  size_t device_bytes_ = 0;
};

}  // namespace seamcl
