#include "pipeline/stages/downsample_launcher.h"

#include <stdexcept>

#include "pipeline/stages/stage_buffers.h"

namespace seamcl {
namespace {
constexpr size_t kGroupSide = 16;
}  // namespace

void DownsampleLauncher::build_kernels() {
  if (rows_() != nullptr) return;
  const cl::Program& program = runtime_.program(KernelProgram::Downsample);
  rows_ = cl::Kernel(program, "downsample_rows");
  columns_ = cl::Kernel(program, "downsample_columns");
}

void DownsampleLauncher::enqueue(const cl::Buffer& image, int width, int height, const DownsampleTaps& taps,
                                 std::vector<glm::vec4>& out, std::vector<cl::Event>& passes,
                                 std::vector<cl::Event>& readback) {
  const int f = taps.factor;
  if (f < 1 || width < f || height < f || width % f != 0 || height % f != 0 || taps.weights.empty() ||
      taps.weights.size() > 64) {
    throw std::invalid_argument("downsample: " + std::to_string(width) + "x" + std::to_string(height) +
                                " is not a multiple of " + std::to_string(f));
  }
  build_kernels();
  const int out_w = width / f, out_h = height / f;
  cl::CommandQueue& queue = runtime_.queue();
  weights_ = cl::Buffer(runtime_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, taps.weights.size() * sizeof(float),
                        const_cast<float*>(taps.weights.data()));
  grow_buffer(mid_, mid_capacity_, static_cast<size_t>(out_w) * height, sizeof(cl_float4), runtime_.context());
  grow_buffer(out_, out_capacity_, static_cast<size_t>(out_w) * out_h, sizeof(cl_float4), runtime_.context());
  const cl_int taps_n = static_cast<cl_int>(taps.weights.size());
  rows_.setArg(0, image);
  rows_.setArg(1, cl_int{width});
  rows_.setArg(2, cl_int{height});
  rows_.setArg(3, cl_int{out_w});
  rows_.setArg(4, cl_int{f});
  rows_.setArg(5, cl_int{taps.first});
  rows_.setArg(6, taps_n);
  rows_.setArg(7, weights_);
  rows_.setArg(8, mid_);
  // A fixed work-group (the kernels skip the items past the edge): with the driver's choice, which
  // follows the image size, PoCL compiles both kernels again for every new size.
  const cl::NDRange group(kGroupSide, kGroupSide);
  queue.enqueueNDRangeKernel(rows_, cl::NullRange, cl::NDRange(round_up(out_w, kGroupSide), round_up(height, kGroupSide)),
                             group, nullptr, &passes.emplace_back());
  columns_.setArg(0, mid_);
  columns_.setArg(1, cl_int{height});
  columns_.setArg(2, cl_int{out_w});
  columns_.setArg(3, cl_int{out_h});
  columns_.setArg(4, cl_int{f});
  columns_.setArg(5, cl_int{taps.first});
  columns_.setArg(6, taps_n);
  columns_.setArg(7, weights_);
  columns_.setArg(8, out_);
  queue.enqueueNDRangeKernel(columns_, cl::NullRange, cl::NDRange(round_up(out_w, kGroupSide), round_up(out_h, kGroupSide)),
                             group, nullptr, &passes.emplace_back());
  out.resize(static_cast<size_t>(out_w) * out_h);
  queue.enqueueReadBuffer(out_, CL_FALSE, 0, out.size() * sizeof(cl_float4), out.data(), nullptr,
                          &readback.emplace_back());
}

void DownsampleLauncher::release() {
  weights_ = mid_ = out_ = cl::Buffer();
  mid_capacity_ = out_capacity_ = 0;
}

size_t DownsampleLauncher::device_bytes() const {
  return buffer_bytes(weights_) + buffer_bytes(mid_) + buffer_bytes(out_);
}

}  // namespace seamcl
