#include "image_io.h"

#include <cstdio>
#include <filesystem>
#include <stdexcept>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include "errors.h"

namespace seamcl {
namespace {

OIIO::ImageBuf linear_buffer(int width, int height, const std::vector<glm::vec4>& pixels) {
  if (pixels.size() != static_cast<size_t>(width) * height) throw std::logic_error("image size mismatch");
  OIIO::ImageSpec spec(width, height, 4, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf buffer(spec);
  buffer.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::FLOAT, pixels.data());
  return buffer;
}

// The buffer to write for a format: sRGB 8-bit for PNG, linear half for EXR.
OIIO::ImageBuf encoded_buffer(ImageFormat format, int width, int height, const std::vector<glm::vec4>& pixels) {
  OIIO::ImageBuf linear = linear_buffer(width, height, pixels);
  if (format == ImageFormat::Exr) {
    linear.set_write_format(OIIO::TypeDesc::HALF);
    return linear;
  }
  OIIO::ImageBuf srgb;
  if (!OIIO::ImageBufAlgo::colorconvert(srgb, linear, "linear", "sRGB")) {
    throw std::runtime_error("sRGB conversion failed: " + srgb.geterror());
  }
  srgb.set_write_format(OIIO::TypeDesc::UINT8);
  return srgb;
}

}  // namespace

ImageFormat image_format_for_path(const std::string& path, const std::string& field) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".png") return ImageFormat::Png;
  if (extension == ".exr") return ImageFormat::Exr;
  throw InputError(field, "must end in .png or .exr, got '" + path + "'");
}

void write_image(const std::string& path, int width, int height, const std::vector<glm::vec4>& pixels) {
  const ImageFormat format = image_format_for_path(path);
  OIIO::ImageBuf buffer = encoded_buffer(format, width, height, pixels);
  const std::string temporary = path + ".partial." + to_string(format);
  if (!buffer.write(temporary, OIIO::TypeUnknown, to_string(format))) {
    std::remove(temporary.c_str());
    throw std::runtime_error("cannot write " + path + ": " + buffer.geterror());
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::remove(temporary.c_str());
    throw std::runtime_error("cannot write " + path + ": " + error.message());
  }
}

std::string encode_image(ImageFormat format, int width, int height, const std::vector<glm::vec4>& pixels) {
  OIIO::ImageBuf buffer = encoded_buffer(format, width, height, pixels);
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput memory(bytes);
  auto output = OIIO::ImageOutput::create(to_string(format));
  if (!output) throw std::runtime_error("no " + to_string(format) + " writer: " + OIIO::geterror());
  OIIO::ImageSpec spec = buffer.spec();
  spec.set_format(format == ImageFormat::Png ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::HALF);
  // The attribute holds a pointer: OIIO reads the address of our pointer to the proxy.
  void* proxy = &memory;
  spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  if (!output->open("memory." + to_string(format), spec) || !buffer.write(output.get()) || !output->close()) {
    throw std::runtime_error("encoding " + to_string(format) + " failed: " + output->geterror());
  }
  return std::string(bytes.begin(), bytes.end());
}

std::vector<glm::vec4> read_image(const std::string& path, int& width, int& height) {
  OIIO::ImageBuf input(path);
  if (!input.read(0, 0, true, OIIO::TypeDesc::FLOAT)) throw std::runtime_error("cannot read " + path + ": " + input.geterror());
  OIIO::ImageBuf linear = input;
  const std::string colorspace = input.spec().get_string_attribute("oiio:ColorSpace");
  if (colorspace == "sRGB") {
    if (!OIIO::ImageBufAlgo::colorconvert(linear, input, "sRGB", "linear")) {
      throw std::runtime_error("cannot convert " + path + " to linear: " + linear.geterror());
    }
  }
  width = linear.spec().width;
  height = linear.spec().height;
  const int channels = linear.spec().nchannels;
  std::vector<float> values(static_cast<size_t>(width) * height * channels);
  linear.get_pixels(OIIO::ROI(0, width, 0, height, 0, 1, 0, channels), OIIO::TypeDesc::FLOAT, values.data());
  std::vector<glm::vec4> pixels(static_cast<size_t>(width) * height, glm::vec4(0, 0, 0, 1));
  for (size_t i = 0; i < pixels.size(); ++i) {
    for (int c = 0; c < std::min(channels, 4); ++c) pixels[i][c] = values[i * channels + c];
  }
  return pixels;
}

}  // namespace seamcl
