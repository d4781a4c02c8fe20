#include <seamcl/io/image_io.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include <seamcl/core/input_error.h>
#include "core/srgb.h"
#include "io/image_codec.h"

namespace seamcl {
namespace {

// The pixels as a format stores them: sRGB 8-bit for PNG (encoded with encode_srgb8, the one
// sRGB encoding of the project: a table, cheaper than OIIO's per-pixel colour conversion),
// linear float for EXR (stored as half, or as float when some value lies beyond
// half's range, 65504, which half would store as infinity).
struct Encoded {
  ImageLevel level;
  ImageWriteOptions options;
  std::vector<uint8_t> srgb8;  // PNG
};

Encoded encode_pixels(ImageFormat format, int width, int height, const std::vector<glm::vec4>& pixels) {
  if (pixels.size() != static_cast<size_t>(width) * height) throw std::logic_error("image size mismatch");
  Encoded out;
  out.level.width = width;
  out.level.height = height;
  if (format == ImageFormat::Exr) {
    constexpr float kLargestHalf = 65504.0f;
    const bool fits_half = std::all_of(pixels.begin(), pixels.end(), [](const glm::vec4& p) {
      return !(std::fabs(p.x) > kLargestHalf || std::fabs(p.y) > kLargestHalf || std::fabs(p.z) > kLargestHalf ||
               std::fabs(p.w) > kLargestHalf);
    });
    out.level.stored = fits_half ? StoredPixels::Half : StoredPixels::Float;
    out.level.pixels = &pixels.front().x;
    return out;
  }
  out.level.stored = StoredPixels::Uint8;
  // zlib level 1: higher levels cost more time for files barely smaller, and the HTTP service
  // pays this on every image (docs/performance.md, "service" rows).
  out.options.png_compression_level = 1;
  out.srgb8.resize(pixels.size() * 4);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const uint32_t packed = encode_srgb8(pixels[i]);
    for (int c = 0; c < 4; ++c) out.srgb8[4 * i + static_cast<size_t>(c)] = static_cast<uint8_t>(packed >> (8 * c));
  }
  out.level.pixels = out.srgb8.data();
  return out;
}

// Writes to `path`, or into `memory` when it is not null.
void write_encoded(const Encoded& encoded, ImageFormat format, const std::string& path, std::string* memory) {
  image_codec().write(path, to_string(format), {encoded.level}, encoded.options, memory);
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
    write_encoded(encode_pixels(format, width, height, pixels), format, temporary, nullptr);
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
  std::string bytes;
  write_encoded(encode_pixels(format, width, height, pixels), format, "memory." + to_string(format), &bytes);
  return bytes;
}

namespace {

// The file opened for reading: its header is read, none of its pixels yet.
std::unique_ptr<ImageSource> open_image(const std::string& path) {
  // A FIFO or a device would block the open or the read until something wrote to it. OpenImageIO
  // opens by path itself, so a path swapped for a FIFO between this check and its open still
  // blocks there (the readers that open files themselves close that gap: core/regular_file.h).
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw std::runtime_error("cannot read " + path + ": no such file");
  if (!std::filesystem::is_regular_file(path, error)) throw std::runtime_error("cannot read " + path + ": not a regular file");
  return image_codec().open(path);
}

ImageHeader header_of(const ImageSource& source) {
  constexpr uint64_t kReadChunkBytes = uint64_t{64} << 20;  // OpenImageIO's ImageInput::read_image's
  const uint64_t chunk = std::min(source.stored_bytes(), kReadChunkBytes);
  return ImageHeader{source.width(), source.height(), source.channels(), static_cast<size_t>(chunk + chunk / 4)};
}

}  // namespace

ImageHeader read_image_header(const std::string& path) { return header_of(*open_image(path)); }

std::vector<glm::vec4> read_image(const std::string& path, int& width, int& height,
                                  const std::function<void(const ImageHeader&)>& check_header) {
  // One open file for the header check and the pixels: the pixels decoded are those of the header
  // the caller saw, whatever happens to the path meanwhile.
  const std::unique_ptr<ImageSource> input = open_image(path);
  if (check_header) check_header(header_of(*input));
  if (input->width() < 1 || input->height() < 1 || input->channels() < 1)
    throw std::runtime_error("cannot read " + path + ": it holds no pixels");
  width = input->width();
  height = input->height();
  const int channels = input->channels();
  // Channels 0..3 straight into x, y, z, w of each pixel (the rest keep 0, 0, 0, 1): the only
  // float copy of the pixels (OpenImageIO converts from the stored format chunk by chunk),
  // converted to linear in place (alpha, a stored one or the 1 above, is not converted) ...
  std::vector<glm::vec4> pixels(static_cast<size_t>(width) * height, glm::vec4(0, 0, 0, 1));
  input->read(pixels.data(), true);
  // ... and grey (with alpha in y) spread to RGB.
  if (channels <= 2)
    for (glm::vec4& p : pixels) p = glm::vec4(glm::vec3(p.x), channels == 2 ? p.y : 1.0f);
  return pixels;
}

}  // namespace seamcl
