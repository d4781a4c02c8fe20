// sRGB 8-bit encoding and decoding, one definition for every side: the kernels decode through
// the same table (uploaded as a buffer), the twins and the image writer encode with the same
// rounding.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

namespace seamcl {

// The sRGB decode both sides use (the kernels get this table as a buffer).
const std::array<float, 256>& srgb_to_linear_table();
// Linear RGBA in [0,1] -> RGBA8 packed r | g << 8 | b << 16 | a << 24, RGB sRGB-encoded.
uint32_t encode_srgb8(const glm::vec4& linear);
// The same for `count` texels, into packed[0 .. count).
void encode_srgb8(const glm::vec4* linear, size_t count, uint32_t* packed);
glm::vec4 decode_srgb8(uint32_t packed);

}  // namespace seamcl
