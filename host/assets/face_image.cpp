#include <seamcl/assets/face_image.h>

#include <algorithm>
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

// Throws unless the file on disk still has the stamp it had when the scene was read.
void check_unchanged(const FaceImageFile& file) {
  const std::optional<FileStamp> now = file_stamp(file.path);
  if (!now) throw InputError(file.field, "image '" + file.path + "' is gone (it was there when the scene was read)");
  if (*now != file.stamp)
    throw InputError(file.field, "image '" + file.path + "' changed since the scene was read (" +
                                     (now->bytes != file.stamp.bytes ? std::to_string(file.stamp.bytes) + " -> " +
                                                                           std::to_string(now->bytes) + " bytes"
                                                                     : std::string("modified again")) +
                                     "); load the scene again");
}

}  // namespace

FaceImageFile open_face_image(const std::string& path, const std::string& field) {
  FaceImageFile file;
  file.path = path;
  file.field = field;
  // The stamp first: a file changed while its header is read then fails the later check.
  const std::optional<FileStamp> stamp = file_stamp(path);
  if (!stamp) throw InputError(field, "image '" + path + "' is not a regular file that can be read");
  file.stamp = *stamp;
  try {
    const ImageHeader header = read_image_header(path);
    file.width = header.width;
    file.height = header.height;
    file.channels = header.channels;
    file.decode_bytes = header.decode_bytes;
  } catch (const std::exception& error) {
    throw InputError(field, error.what());
  }
  check_side(file.width, "wide", path, field);
  check_side(file.height, "high", path, field);
  return file;
}

TextureLevel read_face_image(const FaceImageFile& file) {
  check_unchanged(file);
  // The header of the file as opened for the read, checked before any pixel is decoded: a file
  // swapped since the stamp check (for one of the same stamp, or between the check and the open)
  // is refused at its header, not decoded at whatever size it now has.
  const auto same_header = [&file](const ImageHeader& header) {
    check_side(header.width, "wide", file.path, file.field);
    check_side(header.height, "high", file.path, file.field);
    if (header.width != file.width || header.height != file.height || header.channels != file.channels)
      throw InputError(file.field, "image '" + file.path + "' changed since the scene was read (" +
                                       std::to_string(file.width) + "x" + std::to_string(file.height) + ", " +
                                       std::to_string(file.channels) + " channels -> " + std::to_string(header.width) +
                                       "x" + std::to_string(header.height) + ", " + std::to_string(header.channels) +
                                       " channels); load the scene again");
  };
  int width = 0, height = 0;
  std::vector<glm::vec4> pixels;
  try {
    pixels = read_image(file.path, width, height, same_header);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& error) {
    throw InputError(file.field, error.what());
  }
  if (width != file.width || height != file.height)  // read_image keeps to the header it showed
    throw std::logic_error("read_face_image: read " + std::to_string(width) + "x" + std::to_string(height) +
                           " pixels after a header of " + std::to_string(file.width) + "x" + std::to_string(file.height));
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
