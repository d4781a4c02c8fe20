// Image files: in-memory encoding gives the same bytes as writing a file, formats by extension,
// and a failed write leaves nothing behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <seamcl/core/input_error.h>
#include <seamcl/io/image_io.h>

using namespace seamcl;

namespace {

std::vector<glm::vec4> gradient(int width, int height) {
  std::vector<glm::vec4> pixels;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      pixels.emplace_back(static_cast<float>(x) / static_cast<float>(width), static_cast<float>(y) / static_cast<float>(height),
                          0.25f, 1.0f);
    }
  }
  return pixels;
}

std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

TEST(ImageIo, InMemoryEncodingEqualsTheFile) {
  const auto dir = std::filesystem::temp_directory_path() / ("seamcl-image-io-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::vector<glm::vec4> pixels = gradient(37, 21);
  for (ImageFormat format : {ImageFormat::Png, ImageFormat::Exr}) {
    const auto path = dir / ("image." + to_string(format));
    write_image(path.string(), 37, 21, pixels);
    const std::string memory = encode_image(format, 37, 21, pixels);
    EXPECT_FALSE(memory.empty());
    if (format == ImageFormat::Png) EXPECT_EQ(memory, file_bytes(path));  // EXR headers may differ
    int w = 0, h = 0;
    const std::vector<glm::vec4> back = read_image(path.string(), w, h);
    ASSERT_EQ(w, 37);
    ASSERT_EQ(h, 21);
    // PNG is 8-bit sRGB, EXR half float: both decode close to the linear input.
    const float tolerance = format == ImageFormat::Png ? 0.01f : 1e-3f;
    for (size_t i = 0; i < pixels.size(); ++i) {
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(back[i][c], pixels[i][c], tolerance) << i;
    }
  }
  std::filesystem::remove_all(dir);
}

// EXR stores half floats, whose largest is 65504; an image with a larger value (a bright light on
// a bright texture) is stored as float instead, so it reads back rather than turning infinite.
TEST(ImageIo, ExrKeepsValuesBeyondHalfRange) {
  const auto dir = std::filesystem::temp_directory_path() / ("seamcl-image-io-hdr-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::vector<glm::vec4> pixels = gradient(8, 4);
  pixels[5] = glm::vec4(1e6f, 70000.0f, 3.25f, 1.0f);
  const std::string path = (dir / "bright.exr").string();
  write_image(path, 8, 4, pixels);
  int w = 0, h = 0;
  const std::vector<glm::vec4> back = read_image(path, w, h);
  ASSERT_EQ(back.size(), pixels.size());
  EXPECT_EQ(back[5].x, 1e6f);
  EXPECT_EQ(back[5].y, 70000.0f);
  for (size_t i = 0; i < pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(back[i][c], pixels[i][c]) << i << " " << c;  // float: exact
  std::filesystem::remove_all(dir);
}

TEST(ImageIo, FormatComesFromTheExtension) {
  EXPECT_EQ(image_format_for_path("a/b.PNG"), ImageFormat::Png);
  EXPECT_EQ(image_format_for_path("x.exr"), ImageFormat::Exr);
  try {
    image_format_for_path("x.bmp", "output");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "output");
  }
}

TEST(ImageIo, FailedWriteLeavesNoFile) {
  const auto dir = std::filesystem::temp_directory_path() / ("seamcl-image-io-missing-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  EXPECT_THROW(write_image((dir / "sub" / "x.png").string(), 4, 4, gradient(4, 4)), std::runtime_error);
  EXPECT_FALSE(std::filesystem::exists(dir));
}
