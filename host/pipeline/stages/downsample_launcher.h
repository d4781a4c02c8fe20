// The downsample stage's launcher (kernels/downsample.cl): reduces an image already on the device
// (the shade stage's) by the taps' factor, rows then columns, and reads back the small image
// only. Its intermediate holds width / factor x height pixels.
#pragma once
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/cl/cl_runtime.h>
#include "pipeline/stages/downsample_twin.h"

namespace seamcl {

class DownsampleLauncher {
 public:
  explicit DownsampleLauncher(ClRuntime& runtime) : runtime_(runtime) {}

  // Queues both passes over `image` (width x height RGBA floats) and the read of the result into
  // `out` (resized here); the events of the passes go to `passes`, the read's to `readback`.
  // std::invalid_argument for sizes that are not multiples of the factor.
  void enqueue(const cl::Buffer& image, int width, int height, const DownsampleTaps& taps, std::vector<glm::vec4>& out,
               std::vector<cl::Event>& passes, std::vector<cl::Event>& readback);

  void release();
  size_t device_bytes() const;

 private:
  ClRuntime& runtime_;
  void build_kernels();  // on first use
  cl::Kernel rows_, columns_;
  cl::Buffer weights_, mid_, out_;
  size_t mid_capacity_ = 0, out_capacity_ = 0;
};

}  // namespace seamcl
