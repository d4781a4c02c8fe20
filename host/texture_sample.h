// Texel encoding and the scalar twin of kernels/texture_sample.cl: the sampler every seam
// method is a setting of (filter, address mode, renormalisation).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "gpu_types.h"

namespace seamcl {

// The sRGB decode both sides use (the kernels get this table as a buffer).
const std::array<float, 256>& srgb_to_linear_table();
// Linear RGBA in [0,1] -> RGBA8 packed r | g << 8 | b << 16 | a << 24, RGB sRGB-encoded.
uint32_t encode_srgb8(const glm::vec4& linear);
glm::vec4 decode_srgb8(uint32_t packed);

enum class TexelFormat { Rgba8, Rgba32f };

// The textures as the kernels see them (see FaceGpu in kernels/seamcl_types.h): one of the two
// texel arrays is used, as `format` says.
struct TextureView {
  const std::vector<FaceGpu>* faces;
  const std::vector<FaceNeighbors>* neighbors;  // read by traverse only
  const std::vector<uint32_t>* level_offsets;
  TexelFormat format;
  const std::vector<uint32_t>* texels8;   // RGBA8 sRGB
  const std::vector<float>* texels32;     // linear RGBA32F, 4 floats a texel
  int guard_band = 0;                     // texels of band stored around every level (guardband)
};

// Filtered colour and the summed weight of the taps inside the face (1 unless border).
struct FilterSum {
  glm::vec4 color{0.0f};
  float weight = 0.0f;
};

// log2 within 5e-6 for x > 0, the polynomial the kernels use.
float approx_log2(float x);

FilterSum filter_texture_reference(const TextureView& textures, uint32_t face, const SamplerParams& sampler,
                                   int address, float u, float v, float dudx, float dvdx, float dudy, float dvdy);
// What a method sums before renormalising: filter_texture_reference on the face with the
// sampler's address mode and, for traverse, on each edge neighbour (border) through its uv
// transform.
FilterSum method_sum_reference(const TextureView& textures, uint32_t face, const SamplerParams& sampler, float u, float v,
                               float dudx, float dvdx, float dudy, float dvdy);
// The lookup as a seam method asks for it (renormalisation and zero-coverage rule included).
glm::vec4 sample_texture_reference(const TextureView& textures, uint32_t face, const SamplerParams& sampler, float u,
                                   float v, float dudx, float dvdx, float dudy, float dvdy);

}  // namespace seamcl
