// Image files through OpenImageIO: PNG as sRGB 8-bit, EXR as linear half/float.
#pragma once
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/options/render_options.h>

namespace seamcl {

// The format named by the file's extension (.png, .exr); InputError(field) otherwise.
ImageFormat image_format_for_path(const std::string& path, const std::string& field = "output");

// Writes linear RGBA pixels (row 0 at the top). Writes to a temporary file beside `path` and
// renames it, so a failed write leaves no partial file. Throws std::runtime_error on failure.
void write_image(const std::string& path, int width, int height, const std::vector<glm::vec4>& pixels);

// The same encoding in memory (for the HTTP service).
std::string encode_image(ImageFormat format, int width, int height, const std::vector<glm::vec4>& pixels);

// What an image file's header says, before any pixel is decoded.
struct ImageHeader {
  int width = 0;
  int height = 0;
  int channels = 0;  // as stored (read_image keeps the first 4)
  // About the most that read_image holds beside its result while it decodes the file: its pixels
  // in their stored format, which OpenImageIO converts in chunks of up to 64 MiB, and a quarter
  // more for the format's own reader (measured with OpenImageIO 2.4: PNG and EXR at 2048^2 and
  // 4096^2 held 3-19% over the chunk).
  size_t decode_bytes = 0;
};

// The header alone, so that a caller can refuse a huge image before reading its pixels. Throws
// std::runtime_error when the file is not an image OpenImageIO reads.
ImageHeader read_image_header(const std::string& path);

// Reads any image OpenImageIO can, as linear RGBA float (PNG/JPEG decoded from sRGB). Grey images
// (one channel, or grey and alpha) become grey RGB; a missing alpha is 1. `check_header`, when
// given, sees the header of the file as opened for the read and may throw to refuse it: nothing
// is decoded or allocated for the pixels before it returns, so a file swapped for a larger one
// after the caller looked at it is refused at its header, not decoded. Throws std::runtime_error
// when the file cannot be read.
std::vector<glm::vec4> read_image(const std::string& path, int& width, int& height,
                                  const std::function<void(const ImageHeader&)>& check_header = {});

}  // namespace seamcl
