#include "pipeline/stages/raster_launcher.h"

#include "pipeline/stages/stage_buffers.h"
#include "pipeline/stages/triangle_setup_launcher.h"

namespace seamcl {

cl::Kernel& RasterLauncher::kernel() {
  if (kernel_() == nullptr) kernel_ = cl::Kernel(runtime_.program(KernelProgram::Geometry), "raster");
  return kernel_;
}

void RasterLauncher::reserve(const FrameParams& p) {
  grow_buffer(sample_triangle_, samples_capacity_, static_cast<size_t>(p.width) * p.height * p.sample_count,
              sizeof(cl_uint), runtime_.context());
}

void RasterLauncher::enqueue(const cl::Buffer& frame_params, const cl::Buffer& setups, const BinningLauncher& binning,
                             const FrameParams& p, std::vector<cl::Event>& events) {
  cl::Kernel& kernel = this->kernel();
  kernel.setArg(0, frame_params);
  kernel.setArg(1, setups);
  kernel.setArg(2, binning.tile_counts());
  kernel.setArg(3, binning.tile_offsets());
  kernel.setArg(4, binning.tile_lists());
  kernel.setArg(5, binning.tile_entry_rows());
  kernel.setArg(6, sample_triangle_);
  // One work-item per tile (kernels/raster.cl walks a tile's list once, a row in a 16-wide vector).
  runtime_.queue().enqueueNDRangeKernel(kernel, cl::NullRange,
                                        cl::NDRange(static_cast<size_t>(p.tiles_x), static_cast<size_t>(p.tiles_y)),
                                        cl::NDRange(1, 1), nullptr, &events.emplace_back());
}

std::vector<uint32_t> RasterLauncher::read_sample_triangles(const FrameParams& p) {
  std::vector<uint32_t> winners =
      read_buffer<uint32_t>(runtime_.queue(), sample_triangle_, static_cast<size_t>(p.width) * p.height * p.sample_count);
  for (uint32_t& slot : winners) slot = input_order_slot(slot, static_cast<uint32_t>(p.input_triangles));
  return winners;
}

void RasterLauncher::release() {
  sample_triangle_ = cl::Buffer();
  samples_capacity_ = 0;
}

size_t RasterLauncher::device_bytes() const { return buffer_bytes(sample_triangle_); }

}  // namespace seamcl
