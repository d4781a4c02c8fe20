#include <seamcl/assets/face_image.h>

#include <stdexcept>

#include <seamcl/core/input_error.h>
#include <seamcl/io/image_io.h>

namespace seamcl {
namespace {

void check_side(int side, const char* which, const std::string& path, const std::string& field) {
  if (side < 1 || side > kMaxFaceImageSide || (side & (side - 1)) != 0)
    throw InputError(field, "image '" + path + "' is " + std::to_string(side) + " texels " + which +
                                "; each side must be a power of two from 1 to " + std::to_string(kMaxFaceImageSide));
}

}  // namespace

TextureLevel read_face_image(const std::string& path, const std::string& field) {
  int width = 0, height = 0;
  std::vector<glm::vec4> pixels;
  try {
    read_image_size(path, width, height);
    check_side(width, "wide", path, field);
    check_side(height, "high", path, field);
    int read_width = 0, read_height = 0;
    pixels = read_image(path, read_width, read_height);
    if (read_width != width || read_height != height)
      throw InputError(field, "image '" + path + "' changed while it was read");
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& error) {
    throw InputError(field, error.what());
  }
  // Image rows run top to bottom; texture rows run from v = 0 upwards.
  TextureLevel level{width, height, std::vector<glm::vec4>(pixels.size())};
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i)
      level.texels[static_cast<size_t>(j) * width + i] = pixels[static_cast<size_t>(height - 1 - j) * width + i];
  return level;
}

}  // namespace seamcl
