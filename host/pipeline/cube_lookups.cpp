#include <seamcl/pipeline/cube_lookups.h>

#include <stdexcept>

#include <seamcl/pipeline/renderer.h>

namespace seamcl {

CubeLookups::CubeLookups(ClRuntime& runtime, const CubeMap& cube, bool border) : runtime_(runtime), size_(cube.size) {
  // The batch kernel does not depend on the patch sampler's build options: the sampling program
  // of the default render's options serves.
  const RenderOptions defaults;
  kernel_ = cl::Kernel(runtime.program(KernelProgram::Sampling, program_options(defaults.texels, sampler_params(defaults))), "cube_lookup_batch");
  std::vector<float> texels = pack_cube_texels(cube, border);
  texels_ = cl::Buffer(runtime.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, texels.size() * sizeof(float),
                       texels.data());
}

std::vector<glm::vec4> CubeLookups::sample(const std::vector<CubeLookup>& lookups, const CubeSampler& sampler,
                                           double* kernel_ms) {
  if (sampler.size != size_) {
    throw std::logic_error("cube sampler of size " + std::to_string(sampler.size) + " on a cube of size " +
                           std::to_string(size_));
  }
  std::vector<glm::vec4> out(lookups.size());
  if (lookups.empty()) return out;
  std::vector<float> packed;
  packed.reserve(lookups.size() * 11);
  for (const CubeLookup& l : lookups) {
    packed.insert(packed.end(), {l.direction.x, l.direction.y, l.direction.z, l.ddx.x, l.ddx.y, l.ddx.z, l.ddy.x,
                                 l.ddy.y, l.ddy.z, l.roughness, l.explicit_lod});
  }
  const cl::Context& context = runtime_.context();
  cl::Buffer input(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, packed.size() * sizeof(float), packed.data());
  cl::Buffer colors(context, CL_MEM_WRITE_ONLY, out.size() * sizeof(cl_float4));
  kernel_.setArg(0, texels_);
  kernel_.setArg(1, sampler);
  kernel_.setArg(2, input);
  kernel_.setArg(3, static_cast<cl_uint>(lookups.size()));
  kernel_.setArg(4, colors);
  const size_t group = 64;
  cl::Event event;
  runtime_.queue().enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange((lookups.size() + group - 1) / group * group),
                                        cl::NDRange(group), nullptr, &event);
  runtime_.queue().enqueueReadBuffer(colors, CL_TRUE, 0, out.size() * sizeof(cl_float4), out.data());
  if (kernel_ms != nullptr) *kernel_ms = event_milliseconds(event);
  return out;
}

}  // namespace seamcl
