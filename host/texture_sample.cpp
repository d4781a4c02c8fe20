#include "texture_sample.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace seamcl {

const std::array<float, 256>& srgb_to_linear_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[i] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

namespace {

// Linear values at which the 8-bit sRGB code steps up: the decode of (k + 0.5) / 255. Encoding
// by counting thresholds equals rounding the exact sRGB curve, without a pow per channel.
const std::array<float, 255>& srgb8_thresholds() {
  static const std::array<float, 255> table = [] {
    std::array<float, 255> t{};
    for (int k = 0; k < 255; ++k) {
      const double c = (k + 0.5) / 255.0;
      t[k] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table;
}

// The code of the smallest float sharing each top-16-bit pattern: a starting point from which
// encode_srgb_channel steps up at most a few codes.
const std::vector<uint8_t>& srgb8_start_codes() {
  static const std::vector<uint8_t> table = [] {
    const auto& t = srgb8_thresholds();
    std::vector<uint8_t> codes(65536, 255);
    for (uint32_t high = 0; high < 65536; ++high) {
      const float x = std::bit_cast<float>(high << 16);
      if (!(x > 0.0f)) {
        codes[high] = 0;
      } else if (x < 1.0f) {
        codes[high] = static_cast<uint8_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin());
      }
    }
    return codes;
  }();
  return table;
}

uint32_t encode_srgb_channel(float linear) {
  if (!(linear > 0.0f)) return 0;  // also NaN
  if (linear >= 1.0f) return 255;
  const auto& t = srgb8_thresholds();
  uint32_t code = srgb8_start_codes()[std::bit_cast<uint32_t>(linear) >> 16];
  while (code < 255 && linear >= t[code]) ++code;
  return code;
}

}  // namespace

uint32_t encode_srgb8(const glm::vec4& linear) {
  const double alpha_clamped = std::isnan(linear.a) ? 0.0 : std::clamp(static_cast<double>(linear.a), 0.0, 1.0);
  const auto alpha = static_cast<uint32_t>(std::lround(alpha_clamped * 255.0));
  return encode_srgb_channel(linear.r) | encode_srgb_channel(linear.g) << 8 | encode_srgb_channel(linear.b) << 16 |
         alpha << 24;
}

glm::vec4 decode_srgb8(uint32_t packed) {
  const auto& table = srgb_to_linear_table();
  return {table[packed & 0xffu], table[(packed >> 8) & 0xffu], table[(packed >> 16) & 0xffu],
          static_cast<float>(packed >> 24) * (1.0f / 255.0f)};
}

namespace {

glm::vec4 bilinear_clamp(const std::vector<uint32_t>& texels, uint32_t level_offset, int width, int height, float u,
                         float v) {
  const float x = std::fmin(std::fmax(u * static_cast<float>(width) - 0.5f, -1.0f), static_cast<float>(width));
  const float y = std::fmin(std::fmax(v * static_cast<float>(height) - 0.5f, -1.0f), static_cast<float>(height));
  const float x_floor = std::floor(x);
  const float y_floor = std::floor(y);
  const float fx = x - x_floor;
  const float fy = y - y_floor;
  const int x0 = std::clamp(static_cast<int>(x_floor), 0, width - 1);
  const int x1 = std::clamp(static_cast<int>(x_floor) + 1, 0, width - 1);
  const int y0 = std::clamp(static_cast<int>(y_floor), 0, height - 1);
  const int y1 = std::clamp(static_cast<int>(y_floor) + 1, 0, height - 1);
  auto texel = [&](int i, int j) { return decode_srgb8(texels.at(level_offset + static_cast<uint32_t>(j * width + i))); };
  return (texel(x0, y0) * (1.0f - fx) + texel(x1, y0) * fx) * (1.0f - fy) +
         (texel(x0, y1) * (1.0f - fx) + texel(x1, y1) * fx) * fy;
}

}  // namespace

float trilinear_lod_reference(const FaceGpu& face, float dudx, float dvdx, float dudy, float dvdy) {
  const float w = static_cast<float>(face.width);
  const float h = static_cast<float>(face.height);
  const float len_x = (dudx * w) * (dudx * w) + (dvdx * h) * (dvdx * h);
  const float len_y = (dudy * w) * (dudy * w) + (dvdy * h) * (dvdy * h);
  const float rho_squared = std::fmax(len_x, len_y);
  const float max_lod = static_cast<float>(face.level_count - 1);
  if (!(rho_squared < std::numeric_limits<float>::infinity())) return max_lod;
  return std::fmin(std::fmax(0.5f * std::log2(std::fmax(rho_squared, 1e-30f)), 0.0f), max_lod);
}

glm::vec4 sample_trilinear_clamp_reference(const TextureView& textures, uint32_t face_index, float u, float v,
                                           float dudx, float dvdx, float dudy, float dvdy) {
  const FaceGpu& face = textures.faces->at(face_index);
  const float lod = trilinear_lod_reference(face, dudx, dvdx, dudy, dvdy);
  const int level0 = static_cast<int>(lod);
  const int level1 = std::min(level0 + 1, face.level_count - 1);
  const float t = lod - static_cast<float>(level0);
  auto level = [&](int l) {
    return bilinear_clamp(*textures.texels, textures.level_offsets->at(face.level_table + static_cast<uint32_t>(l)),
                          std::max(face.width >> l, 1), std::max(face.height >> l, 1), u, v);
  };
  const glm::vec4 c0 = level(level0);
  if (t == 0.0f) return c0;
  return c0 * (1.0f - t) + level(level1) * t;
}

}  // namespace seamcl
