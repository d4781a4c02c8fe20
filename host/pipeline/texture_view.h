// The packed textures as the sampler reads them (the kernels and their scalar twin alike), and
// what one filter returns before renormalising.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/core/uninitialized_allocator.h>
#include <seamcl/options/texel_format.h>
#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {

// The textures as the kernels see them (see FaceGpu in kernels/seamcl_types.h): one of the two
// texel arrays is used, as `format` says.
struct TextureView {
  const std::vector<FaceGpu>* faces;
  const std::vector<FaceNeighbors>* neighbors;  // read by traverse and the seam mask; may be empty
  const std::vector<uint32_t>* level_offsets;
  TexelFormat format;
  const UninitializedVector<uint32_t>* texels8;  // RGBA8 sRGB
  const UninitializedVector<float>* texels32;    // linear RGBA32F, 4 floats a texel
  int guard_band = 0;                     // texels of band stored around every level (guardband)
};

// Filtered colour and the summed weight of the taps inside the face (1 unless border).
struct FilterSum {
  glm::vec4 color{0.0f};
  float weight = 0.0f;
};

}  // namespace seamcl
