// Image files: in-memory encoding gives the same bytes as writing a file, formats by extension,
// a failed write leaves nothing behind, and OpenImageIO is loaded (as a module) with the first
// image only.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include <unistd.h>

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

TEST(ImageIo, AReaderThatFailsSilentlyStillGivesAReason) {
  // A PPM whose header promises 4096x4096 and whose data stops after 3 bytes: OpenImageIO's reader
  // fails with an empty error text.
  const auto path = std::filesystem::temp_directory_path() / ("seamcl-image-io-short-" + std::to_string(::getpid()) + ".ppm");
  std::ofstream(path, std::ios::binary) << "P6\n4096 4096\n255\nabc";
  int width = 0, height = 0;
  try {
    read_image(path.string(), width, height);
    ADD_FAILURE() << "a truncated PPM was read";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("cannot read " + path.string() + ": ", 0), 0u) << message;
    EXPECT_GT(message.size(), ("cannot read " + path.string() + ": ").size() + 10) << "a reason follows: " << message;
  }
  std::filesystem::remove(path);
}

namespace {

// A temporary path the same in the test and in its death-test child, which re-runs the test from its
// start in a process of another id.
std::filesystem::path shared_temporary(const std::string& stem) {
  const std::string variable = "SEAMCL_TEST_TEMPORARY_" + stem;
  if (const char* given = std::getenv(variable.c_str()); given != nullptr) return given;
  const auto path = std::filesystem::temp_directory_path() / ("seamcl-image-io-" + stem + "-" + std::to_string(::getpid()));
  ::setenv(variable.c_str(), path.c_str(), 1);
  return path;
}

bool open_image_io_is_mapped() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line))
    if (line.find("libOpenImageIO") != std::string::npos) return true;
  return false;
}

}  // namespace

// OpenImageIO's ~260 shared libraries are loaded with the first image, not at start: the tests and
// the seamcl command do not link them (host/io/image_codec.h).
TEST(ImageIo, OpenImageIoIsLoadedWithTheFirstImageOnly) {
  // A fresh process ("threadsafe" death tests re-run this binary for this test alone).
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const std::string path = shared_temporary("lazy").string() + ".png";
  EXPECT_EXIT(
      {
        const bool before = open_image_io_is_mapped();
        write_image(path, 4, 4, gradient(4, 4));
        std::exit(!before && open_image_io_is_mapped() ? 0 : 1);
      },
      testing::ExitedWithCode(0), "");
  EXPECT_TRUE(std::filesystem::is_regular_file(path));
  std::filesystem::remove(path);

  FILE* ldd = ::popen(("ldd " + std::string(SEAMCL_BINARY)).c_str(), "r");
  ASSERT_NE(ldd, nullptr);
  std::string libraries;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, ldd)) > 0;) libraries.append(buffer, n);
  EXPECT_EQ(::pclose(ldd), 0);
  EXPECT_NE(libraries.find("libOpenCL"), std::string::npos) << libraries;
  EXPECT_EQ(libraries.find("libOpenImageIO"), std::string::npos) << "seamcl links OpenImageIO:\n" << libraries;
}

TEST(ImageIo, AModuleThatDoesNotLoadIsAnErrorNamingWhereItLooked) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const auto dir = shared_temporary("nomodule");
  std::filesystem::create_directories(dir);
  const std::string bogus = (dir / "libseamcl_oiio.so").string();
  { std::ofstream(bogus) << "not a shared object"; }
  for (const std::string& module : {(dir / "absent.so").string(), bogus}) {
    SCOPED_TRACE(module);
    // In a fresh process: this one may have loaded the module already.
    EXPECT_EXIT(
        {
          ::setenv("SEAMCL_OIIO_MODULE", module.c_str(), 1);
          try {
            write_image((dir / "x.png").string(), 4, 4, gradient(4, 4));
          } catch (const std::runtime_error& e) {
            const std::string what = e.what();
            std::cerr << what;
            const bool named = what.find("SEAMCL_OIIO_MODULE") != std::string::npos &&
                               what.find(module + ": ") != std::string::npos;
            std::exit(named && !std::filesystem::exists(dir / "x.png") ? 0 : 2);
          }
          std::exit(3);
        },
        testing::ExitedWithCode(0), module == bogus ? "not a shared object|invalid ELF|too short" : "no such file");
  }
  std::filesystem::remove_all(dir);
}
