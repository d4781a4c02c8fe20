// Texel encoding and the scalar twin of kernels/texture_sample.cl.
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

// The textures as the kernels see them (see FaceGpu in kernels/seamcl_types.h).
struct TextureView {
  const std::vector<FaceGpu>* faces;
  const std::vector<uint32_t>* level_offsets;
  const std::vector<uint32_t>* texels;
};

float trilinear_lod_reference(const FaceGpu& face, float dudx, float dvdx, float dudy, float dvdy);
glm::vec4 sample_trilinear_clamp_reference(const TextureView& textures, uint32_t face, float u, float v,
                                           float dudx, float dvdx, float dudy, float dvdy);

}  // namespace seamcl
