#include "pipeline/stages/shade_inspect_launcher.h"

#include "pipeline/stages/stage_buffers.h"

namespace seamcl {

std::vector<InspectSample> ShadeInspectLauncher::inspect(const std::string& shading_options, const cl::Buffer& frame_params,
                                                         const cl::Buffer& setups, const ShadeSceneBuffers& scene,
                                                         const cl::Buffer& sample_triangle, const FrameParams& p,
                                                         bool adjacency, const PixelWindow& window) {
  // A program variant of its own (built once per shading variant and cached like the others), so
  // the renders' shading program holds none of this.
  cl::Kernel kernel(runtime_.program(KernelProgram::Shading, shading_options + " -DSEAMCL_INSPECT=1"), "shade_inspect");
  std::vector<InspectSample> records(static_cast<size_t>(window.width) * window.height * p.sample_count);
  cl::Buffer out(runtime_.context(), CL_MEM_WRITE_ONLY, records.size() * sizeof(InspectSample));
  int arg = 0;
  kernel.setArg(arg++, frame_params);
  kernel.setArg(arg++, setups);
  kernel.setArg(arg++, scene.faces);
  kernel.setArg(arg++, scene.neighbors);
  kernel.setArg(arg++, scene.level_offsets);
  kernel.setArg(arg++, scene.texels);
  kernel.setArg(arg++, scene.srgb_table);
  kernel.setArg(arg++, sample_triangle);
  kernel.setArg(arg++, scene.reflective_faces);
  kernel.setArg(arg++, scene.cube_texels);
  kernel.setArg(arg++, scene.displaced);
  for (const cl::Buffer* buffer : {&scene.tess_vertices, &scene.tess_normals}) {
    if (scene.displaced.tessellation > 0) kernel.setArg(arg, *buffer);
    else kernel.setArg(arg, sizeof(cl_mem), nullptr);  // face normals: never read
    ++arg;
  }
  kernel.setArg(arg++, static_cast<cl_int>(adjacency ? 1 : 0));
  kernel.setArg(arg++, static_cast<cl_int>(window.x));
  kernel.setArg(arg++, static_cast<cl_int>(window.y));
  kernel.setArg(arg++, static_cast<cl_int>(window.width));
  kernel.setArg(arg++, static_cast<cl_int>(window.height));
  kernel.setArg(arg++, out);
  cl::CommandQueue& queue = runtime_.queue();
  // A fixed work-group (the kernel skips the items past the window): with the driver's choice,
  // which follows the window's size, PoCL compiles the kernel again for every new window shape.
  const size_t side = 8;
  queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(round_up(window.width, side), round_up(window.height, side)),
                             cl::NDRange(side, side));
  queue.enqueueReadBuffer(out, CL_TRUE, 0, records.size() * sizeof(InspectSample), records.data());
  return records;
}

}  // namespace seamcl
