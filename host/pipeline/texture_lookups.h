// Batches of texture lookups on the device (kernels texture_lookup_batch and
// texture_filter_batch): the sampler on its own, for its tests and its benchmark.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/packed_scene.h>

namespace seamcl {

struct Lookup {
  uint32_t face = 0;
  float u = 0, v = 0;                         // face space
  float dudx = 0, dvdx = 0, dudy = 0, dvdy = 0;  // per pixel
};

class TextureLookups {
 public:
  // Uploads the packed textures (in the packed format) once.
  TextureLookups(ClRuntime& runtime, const PackedScene& textures);

  // Uploads the lookups; later calls run them.
  void set_lookups(const std::vector<Lookup>& lookups);
  // The colours sample_texture returns for each lookup; `kernel_ms` gets the kernel's time. The
  // sampler's guard_band must be the one the textures were packed with.
  std::vector<glm::vec4> sample(const SamplerParams& sampler, double* kernel_ms = nullptr);
  // The FilterSums before renormalisation (colour sums and the weight inside the face).
  std::vector<FilterSum> filter(const SamplerParams& sampler);
  // Off: traverse filters every neighbour, skipping none (the kernels' SEAMCL_TRAVERSE_EARLY_OUT),
  // for the tests that check the early-outs change no bit. On by default, as renders run.
  void set_traverse_early_out(bool on) { traverse_early_out_ = on; }

 private:
  // The kernels of the program variant for a sampler configuration (built on first use).
  struct Kernels {
    cl::Kernel sample, filter;
  };
  Kernels& kernels_for(const SamplerParams& sampler);
  cl::Event run(cl::Kernel& kernel, const SamplerParams& sampler, bool with_weights);

  ClRuntime& runtime_;
  TexelFormat format_;
  int guard_band_;
  std::map<std::string, Kernels> kernels_;
  cl::Buffer faces_, neighbors_, level_offsets_, texels_, srgb_table_, lookups_, colors_, weights_;
  size_t count_ = 0;
  bool traverse_early_out_ = true;
};

}  // namespace seamcl
