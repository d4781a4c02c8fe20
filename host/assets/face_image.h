// A face's texture from an image file, for users whose per-face textures are PNG or EXR tiles
// ("texture": {"image": NAME} in a scene file): any format OpenImageIO reads.
#pragma once
#include <string>

#include <seamcl/scene/scene.h>

namespace seamcl {

inline constexpr int kMaxFaceImageSide = 4096;  // as a JSON face's texture width and height

// Level 0 in linear RGBA (8-bit formats decoded from sRGB, grey copied to RGB), shown upright:
// the image's top row at v = 1, its left column at u = 0. Each side must be a power of two up to
// kMaxFaceImageSide, checked from the header before any pixel is read. Every failure is
// InputError(field) naming the path.
TextureLevel read_face_image(const std::string& path, const std::string& field);

}  // namespace seamcl
