#include <seamcl/pipeline/texture_lookups.h>

#include <algorithm>
#include <stdexcept>

#include <seamcl/pipeline/renderer.h>
#include "core/srgb.h"

namespace seamcl {
namespace {

template <typename T, typename Allocator>
cl::Buffer read_only_buffer(const cl::Context& context, const std::vector<T, Allocator>& data) {
  // One element of padding keeps empty arrays legal (OpenCL refuses zero-sized buffers).
  std::vector<T> padded(data.begin(), data.end());
  if (padded.empty()) padded.resize(1);
  return cl::Buffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, padded.size() * sizeof(T), padded.data());
}

}  // namespace

TextureLookups::TextureLookups(ClRuntime& runtime, const PackedScene& textures)
    : runtime_(runtime), format_(textures.format), guard_band_(textures.guard_band) {
  const cl::Context& context = runtime.context();
  faces_ = read_only_buffer(context, textures.faces);
  neighbors_ = read_only_buffer(context, textures.neighbors);
  level_offsets_ = read_only_buffer(context, textures.level_offsets);
  texels_ = textures.format == TexelFormat::Rgba8 ? read_only_buffer(context, textures.texels8)
                                                  : read_only_buffer(context, textures.texels32);
  const auto& table = srgb_to_linear_table();
  srgb_table_ = read_only_buffer(context, std::vector<float>(table.begin(), table.end()));
}

TextureLookups::Kernels& TextureLookups::kernels_for(const SamplerParams& sampler) {
  if (sampler.guard_band != guard_band_) {
    throw std::logic_error("sampler guard band " + std::to_string(sampler.guard_band) + " on textures packed with " +
                           std::to_string(guard_band_));
  }
  const std::string options =
      program_options(format_, sampler) + (traverse_early_out_ ? "" : " -DSEAMCL_TRAVERSE_EARLY_OUT=0");
  auto it = kernels_.find(options);
  if (it == kernels_.end()) {
    const cl::Program& program = runtime_.program(KernelProgram::Sampling, options);
    it = kernels_.emplace(options, Kernels{cl::Kernel(program, "texture_lookup_batch"),
                                           cl::Kernel(program, "texture_filter_batch")}).first;
  }
  return it->second;
}

void TextureLookups::set_lookups(const std::vector<Lookup>& lookups) {
  std::vector<float> packed;
  packed.reserve(lookups.size() * 7);
  for (const Lookup& l : lookups) {
    packed.insert(packed.end(), {static_cast<float>(l.face), l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy});
  }
  count_ = lookups.size();
  lookups_ = read_only_buffer(runtime_.context(), packed);
  colors_ = cl::Buffer(runtime_.context(), CL_MEM_WRITE_ONLY, std::max<size_t>(count_, 1) * sizeof(cl_float4));
  weights_ = cl::Buffer(runtime_.context(), CL_MEM_WRITE_ONLY, std::max<size_t>(count_, 1) * sizeof(cl_float));
}

cl::Event TextureLookups::run(cl::Kernel& kernel, const SamplerParams& sampler, bool with_weights) {
  // Both batch kernels take the same arguments; texture_filter_batch adds the weights.
  kernel.setArg(0, faces_);
  kernel.setArg(1, neighbors_);
  kernel.setArg(2, level_offsets_);
  kernel.setArg(3, texels_);
  kernel.setArg(4, srgb_table_);
  kernel.setArg(5, sampler);
  kernel.setArg(6, lookups_);
  kernel.setArg(7, static_cast<cl_uint>(count_));
  kernel.setArg(8, colors_);
  if (with_weights) kernel.setArg(9, weights_);
  cl::Event event;
  const size_t group = 64;
  runtime_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange((count_ + group - 1) / group * group),
                                        cl::NDRange(group), nullptr, &event);
  return event;
}

std::vector<glm::vec4> TextureLookups::sample(const SamplerParams& sampler, double* kernel_ms) {
  std::vector<glm::vec4> out(count_);
  if (count_ == 0) return out;
  const cl::Event event = run(kernels_for(sampler).sample, sampler, false);
  runtime_.queue().enqueueReadBuffer(colors_, CL_TRUE, 0, count_ * sizeof(cl_float4), out.data());
  if (kernel_ms != nullptr) *kernel_ms = event_milliseconds(event);
  return out;
}

std::vector<FilterSum> TextureLookups::filter(const SamplerParams& sampler) {
  std::vector<FilterSum> out(count_);
  if (count_ == 0) return out;
  run(kernels_for(sampler).filter, sampler, true);
  std::vector<glm::vec4> colors(count_);
  std::vector<float> weights(count_);
  runtime_.queue().enqueueReadBuffer(colors_, CL_TRUE, 0, count_ * sizeof(cl_float4), colors.data());
  runtime_.queue().enqueueReadBuffer(weights_, CL_TRUE, 0, count_ * sizeof(cl_float), weights.data());
  for (size_t i = 0; i < count_; ++i) out[i] = {colors[i], weights[i]};
  return out;
}

}  // namespace seamcl
