#include "core/srgb.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <vector>

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

}  // namespace seamcl
