#include "io/texture_file.h"

#include "core/srgb.h"

#include <algorithm>
#include <stdexcept>

#include <OpenImageIO/imageio.h>

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
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw std::runtime_error("no writer for " + path + ": " + OIIO::geterror());
  if (!out->supports("mipmap") || !out->supports("tiles")) throw std::runtime_error(path + ": format lacks MIP-mapped tiles");
  const int levels = packed.faces.at(face).level_count;
  for (int l = 0; l < levels; ++l) {
    int w = 0, h = 0;
    const std::vector<float> pixels = packed_level_linear(packed, face, l, w, h);
    OIIO::ImageSpec spec(w, h, 4, OIIO::TypeDesc::FLOAT);
    spec.tile_width = 64;
    spec.tile_height = 64;
    spec.attribute("textureformat", "Plain Texture");
    spec.attribute("compression", "zip");
    const auto mode = l == 0 ? OIIO::ImageOutput::Create : OIIO::ImageOutput::AppendMIPLevel;
    if (!out->open(path, spec, mode) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) {
      throw std::runtime_error("writing " + path + ": " + out->geterror());
    }
  }
  if (!out->close()) throw std::runtime_error("closing " + path + ": " + out->geterror());
}

}  // namespace seamcl
