#include "pipeline/stages/shade_resolve_launcher.h"

#include "pipeline/stages/stage_buffers.h"

namespace seamcl {

void ShadeResolveLauncher::use_program(const std::string& program_options) {
  auto it = kernels_.find(program_options);
  if (it == kernels_.end()) {
    it = kernels_.emplace(program_options, cl::Kernel(runtime_.program(KernelProgram::Shading, program_options), "shade_resolve")).first;
  }
  kernel_ = it->second;
}

void ShadeResolveLauncher::reserve(const FrameParams& p) {
  grow_buffer(image_, pixels_capacity_, static_cast<size_t>(p.width) * p.height, sizeof(cl_float4), runtime_.context());
}

void ShadeResolveLauncher::enqueue(const cl::Buffer& frame_params, const cl::Buffer& setups, const ShadeSceneBuffers& scene,
                                   const cl::Buffer& sample_triangle, const cl::Buffer& stats, const FrameParams& p,
                                   bool with_seam_mask, std::vector<cl::Event>& events) {
  kernel_.setArg(0, frame_params);
  kernel_.setArg(1, setups);
  kernel_.setArg(2, scene.faces);
  kernel_.setArg(3, scene.neighbors);
  kernel_.setArg(4, scene.level_offsets);
  kernel_.setArg(5, scene.texels);
  kernel_.setArg(6, scene.srgb_table);
  kernel_.setArg(7, sample_triangle);
  kernel_.setArg(8, image_);
  kernel_.setArg(9, stats);
  if (with_seam_mask) {
    grow_buffer(seam_mask_, mask_capacity_, static_cast<size_t>(p.width) * p.height, sizeof(cl_uchar), runtime_.context());
    kernel_.setArg(10, seam_mask_);
  } else {
    kernel_.setArg(10, sizeof(cl_mem), nullptr);  // a null buffer: the variant never touches it
  }
  kernel_.setArg(11, scene.reflective_faces);
  kernel_.setArg(12, scene.cube_texels);
  kernel_.setArg(13, scene.ptex);
  int arg = 14;
  for (const cl::Buffer* buffer : {&scene.ptex_faces, &scene.ptex_level_offsets, &scene.ptex_texels}) {
    if ((*buffer)() != nullptr) kernel_.setArg(arg, *buffer);
    else kernel_.setArg(arg, sizeof(cl_mem), nullptr);  // a variant without Ptex never reads it
    ++arg;
  }
  kernel_.setArg(arg++, scene.displaced);
  for (const cl::Buffer* buffer : {&scene.tess_vertices, &scene.tess_normals}) {
    if (scene.displaced.tessellation > 0) kernel_.setArg(arg, *buffer);
    else kernel_.setArg(arg, sizeof(cl_mem), nullptr);  // face normals: never read
    ++arg;
  }
  const cl::NDRange tile_grid(static_cast<size_t>(p.tiles_x) * SEAMCL_TILE_SIZE, static_cast<size_t>(p.tiles_y) * SEAMCL_TILE_SIZE);
  const cl::NDRange tile_group(SEAMCL_TILE_SIZE, SEAMCL_TILE_SIZE);
  runtime_.queue().enqueueNDRangeKernel(kernel_, cl::NullRange, tile_grid, tile_group, nullptr, &events.emplace_back());
}

void ShadeResolveLauncher::enqueue_readback(const FrameParams& p, std::vector<glm::vec4>& pixels, std::vector<uint8_t>* mask,
                                            std::vector<cl::Event>& events) {
  cl::CommandQueue& queue = runtime_.queue();
  pixels.resize(static_cast<size_t>(p.width) * p.height);
  queue.enqueueReadBuffer(image_, CL_FALSE, 0, pixels.size() * sizeof(cl_float4), pixels.data(), nullptr, &events.emplace_back());
  if (mask) {
    mask->resize(pixels.size());
    queue.enqueueReadBuffer(seam_mask_, CL_FALSE, 0, mask->size(), mask->data(), nullptr, &events.emplace_back());
  }
}

void ShadeResolveLauncher::release() {
  image_ = seam_mask_ = cl::Buffer();
  pixels_capacity_ = mask_capacity_ = 0;
}

size_t ShadeResolveLauncher::device_bytes() const { return buffer_bytes(image_) + buffer_bytes(seam_mask_); }

}  // namespace seamcl
