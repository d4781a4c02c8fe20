#include "pipeline/stages/triangle_setup_launcher.h"

#include <algorithm>

#include "pipeline/stages/stage_buffers.h"

namespace seamcl {

cl::Kernel& TriangleSetupLauncher::kernel() {
  if (kernel_() == nullptr) kernel_ = cl::Kernel(runtime_.program(KernelProgram::Geometry), "triangle_setup");
  return kernel_;
}

void TriangleSetupLauncher::reserve(size_t input_triangles) {
  const cl::Context& context = runtime_.context();
  grow_buffer(setups_, setups_capacity_, input_triangles * SEAMCL_CLIP_SLOTS, sizeof(TriangleSetup), context);
  grow_buffer(slot_counts_, slot_counts_capacity_, input_triangles, sizeof(cl_uint), context);
}

void TriangleSetupLauncher::enqueue(const cl::Buffer& frame_params, const cl::Buffer& positions, const cl::Buffer& faces,
                                    const cl::Buffer& stats, int input_triangles, std::vector<cl::Event>& events) {
  if (input_triangles <= 0) return;
  cl::Kernel& kernel = this->kernel();
  kernel.setArg(0, frame_params);
  kernel.setArg(1, positions);
  kernel.setArg(2, faces);
  kernel.setArg(3, setups_);
  kernel.setArg(4, slot_counts_);
  kernel.setArg(5, stats);
  const size_t setup_items = (static_cast<size_t>(input_triangles) + SEAMCL_SETUP_LANES - 1) / SEAMCL_SETUP_LANES;
  runtime_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(round_up(setup_items, SEAMCL_SETUP_GROUP)),
                                        cl::NDRange(SEAMCL_SETUP_GROUP), nullptr, &events.emplace_back());
}

std::vector<TriangleSetup> TriangleSetupLauncher::read_setups(size_t triangles, size_t triangles_per_face) {
  cl::CommandQueue& queue = runtime_.queue();
  const std::vector<TriangleSetup> slot_major = read_buffer<TriangleSetup>(queue, setups_, triangles * SEAMCL_CLIP_SLOTS);
  if (slot_major.empty()) return {};
  // Setup writes only a triangle's first slot_counts[t] slots (the rest hold stale data): fill the
  // others with the empty record triangle_setup.cl's store_empty_setup writes, so every slot reads as
  // before. Its face: t's face (two triangles each), or for micro-triangles their patch (2 T^2 each).
  const std::vector<uint32_t> written = read_buffer<uint32_t>(queue, slot_counts_, triangles);
  std::vector<TriangleSetup> setups(slot_major.size());
  for (size_t t = 0; t < triangles; ++t) {
    const size_t filled = std::min<size_t>(written[t], SEAMCL_CLIP_SLOTS);
    for (size_t k = 0; k < SEAMCL_CLIP_SLOTS; ++k) {
      TriangleSetup& s = setups[t * SEAMCL_CLIP_SLOTS + k];
      if (k < filled) {
        s = slot_major[k * triangles + t];
        continue;
      }
      s = TriangleSetup{};
      for (int i = 0; i < 3; ++i) s.edge_c[i] = -1;
      s.bbox_max_x = -1;
      s.bbox_max_y = -1;
      s.face = static_cast<uint32_t>(t / triangles_per_face);
    }
  }
  return setups;
}

void TriangleSetupLauncher::release() {
  setups_ = slot_counts_ = cl::Buffer();
  setups_capacity_ = slot_counts_capacity_ = 0;
}

size_t TriangleSetupLauncher::device_bytes() const { return buffer_bytes(setups_) + buffer_bytes(slot_counts_); }

}  // namespace seamcl
