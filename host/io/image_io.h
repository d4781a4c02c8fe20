// Image files through OpenImageIO: PNG as sRGB 8-bit, EXR as linear half/float.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/pipeline/render_options.h>

namespace seamcl {

// The format named by the file's extension (.png, .exr); InputError(field) otherwise.
ImageFormat image_format_for_path(const std::string& path, const std::string& field = "output");

// Writes linear RGBA pixels (row 0 at the top). Writes to a temporary file beside `path` and
// renames it, so a failed write leaves no partial file. Throws std::runtime_error on failure.
void write_image(const std::string& path, int width, int height, const std::vector<glm::vec4>& pixels);

// The same encoding in memory (for the HTTP service).
std::string encode_image(ImageFormat format, int width, int height, const std::vector<glm::vec4>& pixels);

// Reads any image OpenImageIO can, as linear RGBA float (PNG/JPEG decoded from sRGB). Grey images
// (one channel, or grey and alpha) become grey RGB; a missing alpha is 1.
std::vector<glm::vec4> read_image(const std::string& path, int& width, int& height);

// The size of an image file from its header alone, so that a caller can refuse a huge one before
// reading its pixels. Throws std::runtime_error when the file is not an image OpenImageIO reads.
void read_image_size(const std::string& path, int& width, int& height);

}  // namespace seamcl
