// The shade and resolve stage's launcher (kernels/shade_resolve.cl): one work-item per pixel
// shades the fragments raster left in its samples and resolves them into the image (and, in the
// program variant built with SEAMCL_SEAM_MASK, the pixel's seam class), which it keeps for the
// read-back.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {

// What shading reads of the uploaded scene.
struct ShadeSceneBuffers {
  const cl::Buffer& faces;
  const cl::Buffer& neighbors;
  const cl::Buffer& level_offsets;
  const cl::Buffer& texels;
  const cl::Buffer& srgb_table;
  const cl::Buffer& reflective_faces;
  const cl::Buffer& cube_texels;
  // The Ptex variant's .ptx (null buffers elsewhere) and its settings.
  const cl::Buffer& ptex_faces;
  const cl::Buffer& ptex_level_offsets;
  const cl::Buffer& ptex_texels;
  PtexShading ptex;
  // A displaced render lit with the displaced surface's normals (displaced.tessellation > 0): the
  // tessellation stage's vertices and normals (null buffers otherwise).
  DisplacedShading displaced;
  const cl::Buffer& tess_vertices;
  const cl::Buffer& tess_normals;
};

class ShadeResolveLauncher {
 public:
  explicit ShadeResolveLauncher(ClRuntime& runtime) : runtime_(runtime) {}

  // Makes the kernel of the program built with `program_options` the one enqueue runs.
  void use_program(const std::string& program_options);
  // Sizes the image for the frame's pixels.
  void reserve(const FrameParams& p);
  // Queues shading of the frame's pixels; with_seam_mask (a program built with SEAMCL_SEAM_MASK)
  // also sizes and writes the mask. Its event is appended.
  void enqueue(const cl::Buffer& frame_params, const cl::Buffer& setups, const ShadeSceneBuffers& scene,
               const cl::Buffer& sample_triangle, const cl::Buffer& stats, const FrameParams& p, bool with_seam_mask,
               std::vector<cl::Event>& events);
  // Queues the copy of the image (and, when `mask` is given, of the seam mask) to the host; their
  // events are appended.
  void enqueue_readback(const FrameParams& p, std::vector<glm::vec4>& pixels, std::vector<uint8_t>* mask,
                        std::vector<cl::Event>& events);

  // The resolved image of the last frame, for a stage that reads it on the device (downsample).
  const cl::Buffer& image() const { return image_; }

  void release();
  size_t device_bytes() const;

 private:
  ClRuntime& runtime_;
  std::map<std::string, cl::Kernel> kernels_;  // by program options
  cl::Kernel kernel_;
  cl::Buffer image_;
  cl::Buffer seam_mask_;  // only once a render asks for the mask
  size_t pixels_capacity_ = 0, mask_capacity_ = 0;
};

}  // namespace seamcl
