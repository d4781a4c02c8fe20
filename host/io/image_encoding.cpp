#include <seamcl/io/image_encoding.h>

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <seamcl/io/image_io.h>

namespace seamcl {
namespace {

constexpr std::array<std::pair<ImageEncoding, const char*>, 3> kEncodings{
    {{ImageEncoding::Png, "png"}, {ImageEncoding::Exr, "exr"}, {ImageEncoding::F32, "f32"}}};

}  // namespace

const std::vector<std::string>& image_encoding_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& entry : kEncodings) out.emplace_back(entry.second);
    return out;
  }();
  return names;
}

std::optional<ImageEncoding> parse_image_encoding(std::string_view name) {
  for (const auto& [encoding, entry_name] : kEncodings)
    if (name == entry_name) return encoding;
  return std::nullopt;
}

std::string to_string(ImageEncoding encoding) {
  for (const auto& [entry, name] : kEncodings)
    if (entry == encoding) return name;
  throw std::logic_error("unnamed image encoding");
}

std::string media_type(ImageEncoding encoding) {
  switch (encoding) {
    case ImageEncoding::Png: return "image/png";
    case ImageEncoding::Exr: return "image/x-exr";
    case ImageEncoding::F32: return "application/octet-stream";
  }
  throw std::logic_error("unnamed image encoding");
}

std::string encode_f32_rgba(int width, int height, const std::vector<glm::vec4>& pixels) {
  if (width < 0 || height < 0 || pixels.size() != static_cast<size_t>(width) * static_cast<size_t>(height)) {
    throw std::logic_error("image size mismatch");
  }
  std::string out(pixels.size() * 16, '\0');
  char* at = out.data();
  for (const glm::vec4& pixel : pixels) {
    for (int c = 0; c < 4; ++c) {
      const uint32_t bits = std::bit_cast<uint32_t>(pixel[c]);
      for (int byte = 0; byte < 4; ++byte) *at++ = static_cast<char>((bits >> (8 * byte)) & 0xffu);
    }
  }
  return out;
}

std::string encode_image(ImageEncoding encoding, int width, int height, const std::vector<glm::vec4>& pixels) {
  switch (encoding) {
    case ImageEncoding::Png: return encode_image(ImageFormat::Png, width, height, pixels);
    case ImageEncoding::Exr: return encode_image(ImageFormat::Exr, width, height, pixels);
    case ImageEncoding::F32: return encode_f32_rgba(width, height, pixels);
  }
  throw std::logic_error("unnamed image encoding");
}

}  // namespace seamcl
