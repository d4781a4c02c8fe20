#include <seamcl/io/image_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <seamcl/core/input_error.h>
#include "core/srgb.h"

namespace seamcl {
namespace {

// The pixels as a format stores them: sRGB 8-bit for PNG (encoded with encode_srgb8, the one
// sRGB encoding of the project: a table, cheaper than OIIO's per-pixel colour conversion),
// linear float for EXR (stored as half, or as float when some value lies beyond
// half's range, 65504, which half would store as infinity).
struct Encoded {
  OIIO::ImageSpec spec;
  std::vector<uint8_t> srgb8;  // PNG
  const float* linear = nullptr;  // EXR: the caller's pixels

  const void* data() const { return linear != nullptr ? static_cast<const void*>(linear) : srgb8.data(); }
  OIIO::TypeDesc type() const { return linear != nullptr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8; }
};

Encoded encode_pixels(ImageFormat format, int width, int height, const std::vector<glm::vec4>& pixels) {
  if (pixels.size() != static_cast<size_t>(width) * height) throw std::logic_error("image size mismatch");
  Encoded out;
  if (format == ImageFormat::Exr) {
    constexpr float kLargestHalf = 65504.0f;
    const bool fits_half = std::all_of(pixels.begin(), pixels.end(), [](const glm::vec4& p) {
      return !(std::fabs(p.x) > kLargestHalf || std::fabs(p.y) > kLargestHalf || std::fabs(p.z) > kLargestHalf ||
               std::fabs(p.w) > kLargestHalf);
    });
    out.spec = OIIO::ImageSpec(width, height, 4, fits_half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    out.linear = &pixels.front().x;
    return out;
  }
  out.spec = OIIO::ImageSpec(width, height, 4, OIIO::TypeDesc::UINT8);
  // zlib level 1: higher levels cost more time for files barely smaller, and the HTTP service
  // pays this on every image (docs/performance.md, "service" rows).
  out.spec.attribute("png:compressionLevel", 1);
  out.srgb8.resize(pixels.size() * 4);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const uint32_t packed = encode_srgb8(pixels[i]);
    for (int c = 0; c < 4; ++c) out.srgb8[4 * i + static_cast<size_t>(c)] = static_cast<uint8_t>(packed >> (8 * c));
  }
  return out;
}

// Writes through an ImageOutput to `path` (a file, or the in-memory proxy set in the spec).
void write_encoded(const Encoded& encoded, ImageFormat format, const std::string& path) {
  auto output = OIIO::ImageOutput::create(to_string(format));
  if (!output) throw std::runtime_error("no " + to_string(format) + " writer: " + OIIO::geterror());
  if (!output->open(path, encoded.spec) || !output->write_image(encoded.type(), encoded.data()) || !output->close()) {
    throw std::runtime_error("cannot write " + path + ": " + output->geterror());
  }
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
  const std::string temporary = path + ".partial." + to_string(format);
  try {
    write_encoded(encode_pixels(format, width, height, pixels), format, temporary);
  } catch (const std::exception&) {
    std::remove(temporary.c_str());
    throw;
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::remove(temporary.c_str());
    throw std::runtime_error("cannot write " + path + ": " + error.message());
  }
}

std::string encode_image(ImageFormat format, int width, int height, const std::vector<glm::vec4>& pixels) {
  Encoded encoded = encode_pixels(format, width, height, pixels);
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput memory(bytes);
  // The attribute holds a pointer: OIIO reads the address of our pointer to the proxy.
  void* proxy = &memory;
  encoded.spec.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
  write_encoded(encoded, format, "memory." + to_string(format));
  return std::string(bytes.begin(), bytes.end());
}

namespace {

// The file opened for reading: its header is read, none of its pixels yet.
std::unique_ptr<OIIO::ImageInput> open_image(const std::string& path) {
  // A FIFO or a device would block the open or the read until something wrote to it. OpenImageIO
  // opens by path itself, so a path swapped for a FIFO between this check and its open still
  // blocks there (the readers that open files themselves close that gap: core/regular_file.h).
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw std::runtime_error("cannot read " + path + ": no such file");
  if (!std::filesystem::is_regular_file(path, error)) throw std::runtime_error("cannot read " + path + ": not a regular file");
  auto input = OIIO::ImageInput::open(path);
  if (!input) throw std::runtime_error("cannot read " + path + ": " + OIIO::geterror());
  return input;
}

ImageHeader header_of(const OIIO::ImageSpec& spec) {
  constexpr OIIO::imagesize_t kReadChunkBytes = OIIO::imagesize_t{64} << 20;  // ImageInput::read_image's
  const OIIO::imagesize_t chunk = std::min(spec.image_bytes(true), kReadChunkBytes);
  return ImageHeader{spec.width, spec.height, spec.nchannels, static_cast<size_t>(chunk + chunk / 4)};
}

}  // namespace

ImageHeader read_image_header(const std::string& path) { return header_of(open_image(path)->spec()); }

std::vector<glm::vec4> read_image(const std::string& path, int& width, int& height,
                                  const std::function<void(const ImageHeader&)>& check_header) {
  // One open file for the header check and the pixels: the pixels decoded are those of the header
  // the caller saw, whatever happens to the path meanwhile.
  const std::unique_ptr<OIIO::ImageInput> input = open_image(path);
  const OIIO::ImageSpec spec = input->spec();
  if (check_header) check_header(header_of(spec));
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1)
    throw std::runtime_error("cannot read " + path + ": it holds no pixels");
  width = spec.width;
  height = spec.height;
  const int channels = spec.nchannels;
  // Channels 0..3 straight into x, y, z, w of each pixel (the rest keep 0, 0, 0, 1): the only
  // float copy of the pixels (OpenImageIO converts from the stored format chunk by chunk) ...
  std::vector<glm::vec4> pixels(static_cast<size_t>(width) * height, glm::vec4(0, 0, 0, 1));
  const OIIO::stride_t pixel_stride = sizeof(glm::vec4);
  if (!input->read_image(0, 0, 0, std::min(channels, 4), OIIO::TypeDesc::FLOAT, pixels.data(), pixel_stride,
                         pixel_stride * width))
    throw std::runtime_error("cannot read " + path + ": " + input->geterror());
  input->close();
  // ... converted to linear in place (alpha, a stored one or the 1 above, is not converted) ...
  if (spec.get_string_attribute("oiio:ColorSpace") == "sRGB") {
    OIIO::ImageBuf in_place(OIIO::ImageSpec(width, height, 4, OIIO::TypeDesc::FLOAT), pixels.data());
    if (!OIIO::ImageBufAlgo::colorconvert(in_place, in_place, "sRGB", "linear"))
      throw std::runtime_error("cannot convert " + path + " to linear: " + in_place.geterror());
  }
  // ... and grey (with alpha in y) spread to RGB.
  if (channels <= 2)
    for (glm::vec4& p : pixels) p = glm::vec4(glm::vec3(p.x), channels == 2 ? p.y : 1.0f);
  return pixels;
}

}  // namespace seamcl
