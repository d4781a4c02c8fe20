// The 8-bit sRGB encoding every side shares (packed textures, PNG pixels): the exact curve's
// rounding at every step, the ends, linear alpha, and a run encoded at once equal to each texel.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/srgb.h"

using namespace seamcl;

TEST(Srgb8, EncodeRoundsTheExactCurveAtEveryStep) {
  // Code k + 1 starts where the exact curve reaches k + 0.5: just below that linear value the
  // code is k, at it k + 1, for every step (the steps are the decoded half-codes, in float).
  for (int k = 0; k < 255; ++k) {
    const double half_code = (k + 0.5) / 255.0;
    const auto step = static_cast<float>(half_code <= 0.04045 ? half_code / 12.92
                                                              : std::pow((half_code + 0.055) / 1.055, 2.4));
    const float below = std::nextafter(step, 0.0f);
    EXPECT_EQ(encode_srgb8(glm::vec4(below, step, below, 1.0f)), static_cast<uint32_t>(k | (k + 1) << 8 | k << 16 | 255u << 24))
        << "step " << k << " at " << step;
  }
  // Outside [0, 1] and NaN: the ends; every code decodes to a value that encodes to it again.
  EXPECT_EQ(encode_srgb8(glm::vec4(-1.0f, std::numeric_limits<float>::quiet_NaN(), 7.0f, 0.0f)), 0xff0000u);
  EXPECT_EQ(encode_srgb8(glm::vec4(0.0f, 1.0f, std::numeric_limits<float>::infinity(), 1.0f)), 0xffffff00u);
  for (uint32_t code = 0; code < 256; ++code) {
    const uint32_t packed = code | (255 - code) << 8 | code << 16 | code << 24;
    EXPECT_EQ(encode_srgb8(decode_srgb8(packed)), packed) << code;
  }
  // Alpha is linear: 255 a rounded, halves away from zero (as std::lround).
  for (int step = 0; step <= 2550; ++step) {
    const float alpha = static_cast<float>(step) / 2550.0f;
    EXPECT_EQ(encode_srgb8(glm::vec4(0.0f, 0.0f, 0.0f, alpha)) >> 24,
              static_cast<uint32_t>(std::lround(static_cast<double>(alpha) * 255.0)))
        << alpha;
  }
}

TEST(Srgb8, EncodingARunEqualsEncodingEachTexel) {
  std::vector<glm::vec4> texels;
  for (int i = 0; i < 3001; ++i) {
    const float x = static_cast<float>(i) / 3000.0f;
    texels.emplace_back(x, 1.0f - x, x * x, std::fmod(x * 7.0f, 1.0f));
  }
  texels.emplace_back(std::numeric_limits<float>::quiet_NaN(), -0.0f, 2.0f, -3.0f);
  std::vector<uint32_t> packed(texels.size());
  encode_srgb8(texels.data(), texels.size(), packed.data());
  for (size_t i = 0; i < texels.size(); ++i) EXPECT_EQ(packed[i], encode_srgb8(texels[i])) << i;
}

TEST(Srgb8, EveryFloatPatternEncodesAsTheCurveCountsIt) {
  // A code is the number of steps (decoded half-codes) at or below the value: NaN, negatives and
  // zero are 0, 1 and above (+inf too) are 255. Every 4096th bit pattern, both signs, so every
  // top-16-bit bucket of the encoder's table is met 16 times, and each step's neighbours.
  std::vector<float> steps;
  for (int k = 0; k < 255; ++k) {
    const double half_code = (k + 0.5) / 255.0;
    steps.push_back(static_cast<float>(half_code <= 0.04045 ? half_code / 12.92
                                                             : std::pow((half_code + 0.055) / 1.055, 2.4)));
  }
  const auto expected = [&](float x) -> uint32_t {
    if (!(x > 0.0f)) return 0;
    if (x >= 1.0f) return 255;
    return static_cast<uint32_t>(std::upper_bound(steps.begin(), steps.end(), x) - steps.begin());
  };
  std::vector<float> values;
  for (uint64_t bits = 0; bits <= 0xffffffffu; bits += 4096) values.push_back(std::bit_cast<float>(static_cast<uint32_t>(bits)));
  for (float step : steps) {
    values.push_back(std::nextafter(step, 0.0f));
    values.push_back(step);
    values.push_back(std::nextafter(step, 1.0f));
  }
  values.push_back(std::nextafter(1.0f, 0.0f));
  values.push_back(std::numeric_limits<float>::denorm_min());
  values.push_back(-std::numeric_limits<float>::infinity());
  std::vector<glm::vec4> texels;
  for (float x : values) texels.emplace_back(x, 0.0f, 0.0f, 0.0f);
  std::vector<uint32_t> packed(texels.size());
  encode_srgb8(texels.data(), texels.size(), packed.data());
  for (size_t i = 0; i < values.size(); ++i)
    ASSERT_EQ(packed[i], expected(values[i])) << "bits " << std::bit_cast<uint32_t>(values[i]) << " (" << values[i] << ")";
}
