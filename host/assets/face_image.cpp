#include <seamcl/assets/face_image.h>

#include <algorithm>
#include <stdexcept>
#include <system_error>

#include <seamcl/core/input_error.h>
#include <seamcl/io/image_io.h>

namespace seamcl {
namespace {

void check_side(int side, const char* which, const std::string& path, const std::string& field) {
  if (side < 1 || side > kMaxFaceImageSide || (side & (side - 1)) != 0)
    throw InputError(field, "image '" + path + "' is " + std::to_string(side) + " texels " + which +
                                "; each side must be a power of two from 1 to " + std::to_string(kMaxFaceImageSide));
}

// The file's size and modification time; false when it cannot be looked at (gone, not a file).
bool stamp_of(const std::string& path, std::uintmax_t& bytes, std::filesystem::file_time_type& modified) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;
  bytes = std::filesystem::file_size(path, error);
  if (error) return false;
  modified = std::filesystem::last_write_time(path, error);
  return !error;
}

// Throws unless the file on disk still has the stamp it had when the scene was read.
void check_unchanged(const FaceImageFile& file) {
  std::uintmax_t bytes = 0;
  std::filesystem::file_time_type modified{};
  if (!stamp_of(file.path, bytes, modified))
    throw InputError(file.field, "image '" + file.path + "' is gone (it was there when the scene was read)");
  if (bytes != file.file_bytes || modified != file.modified)
    throw InputError(file.field, "image '" + file.path + "' changed since the scene was read (" +
                                     (bytes != file.file_bytes ? std::to_string(file.file_bytes) + " -> " +
                                                                     std::to_string(bytes) + " bytes"
                                                               : std::string("modified again")) +
                                     "); load the scene again");
}

}  // namespace

FaceImageFile open_face_image(const std::string& path, const std::string& field) {
  FaceImageFile file{path, field};
  // The stamp first: a file changed while its header is read then fails the later check.
  if (!stamp_of(path, file.file_bytes, file.modified))
    throw InputError(field, "image '" + path + "' is not a regular file that can be read");
  try {
    read_image_size(path, file.width, file.height);
  } catch (const std::exception& error) {
    throw InputError(field, error.what());
  }
  check_side(file.width, "wide", path, field);
  check_side(file.height, "high", path, field);
  return file;
}

TextureLevel read_face_image(const FaceImageFile& file) {
  check_unchanged(file);
  int width = 0, height = 0;
  std::vector<glm::vec4> pixels;
  try {
    pixels = read_image(file.path, width, height);
  } catch (const std::exception& error) {
    throw InputError(file.field, error.what());
  }
  if (width != file.width || height != file.height)
    throw InputError(file.field, "image '" + file.path + "' changed while it was read (" + std::to_string(file.width) +
                                     "x" + std::to_string(file.height) + " -> " + std::to_string(width) + "x" +
                                     std::to_string(height) + ")");
  check_unchanged(file);  // the pixels read are the stamped file's
  // Image rows run top to bottom; texture rows run from v = 0 upwards: rows swapped in place, so
  // that no second copy of the face's level 0 exists.
  const auto row = [&](int j) { return pixels.begin() + static_cast<std::ptrdiff_t>(j) * width; };
  for (int j = 0; j < height / 2; ++j) std::swap_ranges(row(j), row(j) + width, row(height - 1 - j));
  return TextureLevel{width, height, std::move(pixels)};
}

TextureLevel read_face_image(const std::string& path, const std::string& field) {
  return read_face_image(open_face_image(path, field));
}

}  // namespace seamcl
