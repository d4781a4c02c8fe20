// The encodings an image can be handed out in over the HTTP service. ImageFormat (options/
// render_options.h) names the file formats write_image picks by extension; an encoding adds f32,
// which is no file format: the raw float pixels, which a browser reads into a Float32Array with
// no decoder and no 8-bit rounding.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace seamcl {

// png: sRGB 8-bit; exr: linear half (float where a value is past half's range); f32: linear
// little-endian float32 R, G, B, A per pixel, rows top first, 16 bytes a pixel and no header.
enum class ImageEncoding { Png, Exr, F32 };

// Every encoding's name, in declaration order: what parse_image_encoding takes.
const std::vector<std::string>& image_encoding_names();
std::optional<ImageEncoding> parse_image_encoding(std::string_view name);
std::string to_string(ImageEncoding encoding);
// The HTTP media type of the encoded bytes.
std::string media_type(ImageEncoding encoding);

// `pixels` (width x height, row 0 at the top) in `encoding`. Throws std::logic_error when the
// pixel count is not width x height.
std::string encode_image(ImageEncoding encoding, int width, int height, const std::vector<glm::vec4>& pixels);

// The f32 encoding: byte order fixed (little-endian) whatever the host's.
std::string encode_f32_rgba(int width, int height, const std::vector<glm::vec4>& pixels);

}  // namespace seamcl
