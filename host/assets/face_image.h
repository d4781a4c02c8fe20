// A face's texture from an image file, for users whose per-face textures are PNG or EXR tiles
// ("texture": {"image": NAME} in a scene file): any format OpenImageIO reads.
#pragma once
#include <string>

#include <seamcl/assets/file_stamp.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

inline constexpr int kMaxFaceImageSide = 4096;  // as a JSON face's texture width and height

// An image file as its header described it when a scene named it: enough to size the face's
// texture, and to tell later whether the file is still the one that was looked at.
struct FaceImageFile {
  std::string path;
  std::string field;  // the JSON path to name in errors (faces[3].texture.image)
  int width = 0;
  int height = 0;
  int channels = 0;
  size_t decode_bytes = 0;  // the header's: what decoding the pixels holds beside level 0
  // The file's size and modification time when its header was read: read_face_image refuses a
  // file whose stamp has moved since, so a deferred face never shows other pixels than the ones
  // whose size the scene was checked against.
  FileStamp stamp;
};

// Reads the header only: each side must be a power of two up to kMaxFaceImageSide. Every failure
// (no such file, not an image, a bad size) is InputError(field) naming the path.
FaceImageFile open_face_image(const std::string& path, const std::string& field);

// Level 0 in linear RGBA (8-bit formats decoded from sRGB, grey copied to RGB), shown upright:
// the image's top row at v = 1, its left column at u = 0. The file must still be the one
// open_face_image saw (the same size on disk and modification time, before and after the pixels
// are read, and the same width, height and channels in the header of the file as opened for the
// read, checked before any pixel is decoded): otherwise, or when it has gone or cannot be decoded,
// InputError(file.field) naming the path and what changed.
TextureLevel read_face_image(const FaceImageFile& file);

// open_face_image then read_face_image: a face read at once.
TextureLevel read_face_image(const std::string& path, const std::string& field);

}  // namespace seamcl
