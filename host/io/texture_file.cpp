#include "io/texture_file.h"

#include "core/srgb.h"
#include "io/image_codec.h"

#include <algorithm>
#include <stdexcept>


namespace seamcl {

std::vector<float> packed_level_linear(const PackedScene& packed, uint32_t face, int level, int& width, int& height) {
  const FaceGpu& f = packed.faces.at(face);
  width = std::max(f.width >> level, 1);
  height = std::max(f.height >> level, 1);
  const uint32_t offset = packed.level_offsets.at(f.level_table + static_cast<uint32_t>(level));
  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
  std::vector<float> out(count * 4);
  for (size_t i = 0; i < count; ++i) {
    glm::vec4 t;
    if (packed.format == TexelFormat::Rgba8) {
      t = decode_srgb8(packed.texels8.at(offset + i));
    } else {
      const float* p = &packed.texels32.at(4 * (offset + i));
      t = glm::vec4(p[0], p[1], p[2], p[3]);
    }
    for (int c = 0; c < 4; ++c) out[4 * i + static_cast<size_t>(c)] = t[c];
  }
  return out;
}

void write_face_mip_exr(const PackedScene& packed, uint32_t face, const std::string& path) {
  const int level_count = packed.faces.at(face).level_count;
  std::vector<std::vector<float>> pixels(static_cast<size_t>(level_count));
  std::vector<ImageLevel> levels(static_cast<size_t>(level_count));
  for (int l = 0; l < level_count; ++l) {
    ImageLevel& level = levels[static_cast<size_t>(l)];
    pixels[static_cast<size_t>(l)] = packed_level_linear(packed, face, l, level.width, level.height);
    level.stored = StoredPixels::Float;
    level.pixels = pixels[static_cast<size_t>(l)].data();
  }
  ImageWriteOptions options;
  options.tile_size = 64;
  options.mip_texture = true;
  options.compression = "zip";
  image_codec().write(path, "", levels, options, nullptr);
}

}  // namespace seamcl
