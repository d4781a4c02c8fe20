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
  // alone runs through a kernel of its own (ptex_point_lookups), shorter per lookup; a batch that
  // opens with a point lookup is taken for one, and where another filter follows, the general
  // kernel runs over the whole batch after it.
  std::vector<float> run(const std::vector<PtexFilterQuery>& queries);
  // The same into the caller's memory, 4 * queries.size() floats at `values`: a caller that looks up
  // batch after batch keeps one array (a new one is zeroed and its pages faulted in on one thread).
  void run(const std::vector<PtexFilterQuery>& queries, float* values);

  // Uploads `queries` once (for timing) and runs them `repeats` times back to back; returns the
  // kernel milliseconds of each run (OpenCL profiling events).
  std::vector<double> time(const std::vector<PtexFilterQuery>& queries, int repeats);

  size_t device_bytes() const { return device_bytes_; }

 private:
  // `kernel` with its arguments set to the texture, `in`, `count` and `out` (and, for
  // ptex_point_lookups, not_point_).
  cl::Kernel& with_args(cl::Kernel& kernel, const cl::Buffer& in, size_t count, const cl::Buffer& out);

  ClRuntime& runtime_;
  cl::Kernel kernel_;
  cl::Kernel point_kernel_;
  PtexFilterTexture texture_{};
  cl::Buffer faces_, level_offsets_, texels_;
  cl::Buffer not_point_;  // ptex_point_lookups' flag: a query of another filter was in its batch
  size_t device_bytes_ = 0;
};

}  // namespace seamcl
