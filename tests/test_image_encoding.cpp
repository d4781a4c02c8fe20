// Image encodings for the HTTP service: every name round-trips, and f32 is the pixels' float bits
// in little-endian order, rows top first, whatever the host's byte order.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <seamcl/io/image_encoding.h>

using namespace seamcl;

namespace {

float float_at(const std::string& bytes, size_t offset) {
  uint32_t bits = 0;
  for (int byte = 0; byte < 4; ++byte) bits |= static_cast<uint32_t>(static_cast<unsigned char>(bytes[offset + byte])) << (8 * byte);
  float value = 0;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

}  // namespace

TEST(ImageEncoding, NamesRoundTripAndOthersAreRefused) {
  ASSERT_EQ(image_encoding_names(), (std::vector<std::string>{"png", "exr", "f32"}));
  for (const std::string& name : image_encoding_names()) {
    const std::optional<ImageEncoding> encoding = parse_image_encoding(name);
    ASSERT_TRUE(encoding) << name;
    EXPECT_EQ(to_string(*encoding), name);
  }
  for (const char* bad : {"", "F32", "f16", "png ", "jpeg"}) EXPECT_FALSE(parse_image_encoding(bad)) << bad;
  EXPECT_EQ(media_type(ImageEncoding::Png), "image/png");
  EXPECT_EQ(media_type(ImageEncoding::Exr), "image/x-exr");
  EXPECT_EQ(media_type(ImageEncoding::F32), "application/octet-stream");
}

TEST(ImageEncoding, F32IsLittleEndianRgbaRowsTopFirst) {
  const int width = 3, height = 2;
  std::vector<glm::vec4> pixels;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) pixels.emplace_back(0.125f * x, -2.5f * y, 1e-8f * (x + 1), 70000.0f + static_cast<float>(x + y));
  pixels[4].w = std::numeric_limits<float>::infinity();
  const std::string bytes = encode_image(ImageEncoding::F32, width, height, pixels);
  ASSERT_EQ(bytes.size(), static_cast<size_t>(width * height * 16));
  for (size_t i = 0; i < pixels.size(); ++i)
    for (int c = 0; c < 4; ++c) EXPECT_EQ(float_at(bytes, 16 * i + 4 * c), pixels[i][c]) << i << "," << c;
  // 1.0f is 0x3f800000: its lowest byte first.
  const std::string one = encode_f32_rgba(1, 1, {glm::vec4(1.0f, 0.0f, 0.0f, 0.0f)});
  EXPECT_EQ(one.substr(0, 4), std::string("\x00\x00\x80\x3f", 4));
  EXPECT_EQ(encode_f32_rgba(0, 0, {}), "");
  EXPECT_THROW(encode_f32_rgba(2, 2, pixels), std::logic_error);
}
