#include "packed_scene.h"

#include "adjacency.h"

#include <limits>
#include <stdexcept>

namespace seamcl {

PackedScene pack_scene(const Scene& scene, TexelFormat format) {
  PackedScene out;
  out.format = format;
  out.positions.reserve(scene.positions.size());
  for (const glm::vec3& p : scene.positions) out.positions.push_back({{p.x, p.y, p.z, 1.0f}});
  out.faces.reserve(scene.faces.size());
  if (format == TexelFormat::Rgba8) {
    out.texels8.reserve(scene.texel_count());
  } else {
    out.texels32.reserve(scene.texel_count() * 4);
  }
  size_t texels = 0;
  for (const Face& face : scene.faces) {
    FaceGpu gpu{};
    for (int i = 0; i < 4; ++i) gpu.vertex[i] = face.vertices[i];
    gpu.level_table = static_cast<cl_uint>(out.level_offsets.size());
    gpu.width = face.texture.width();
    gpu.height = face.texture.height();
    gpu.level_count = static_cast<cl_int>(face.texture.levels.size());
    const glm::vec3 n = scene.face_normal(face);
    gpu.normal[0] = n.x;
    gpu.normal[1] = n.y;
    gpu.normal[2] = n.z;
    for (const TextureLevel& level : face.texture.levels) {
      // Offsets are 32-bit texel indices (and 4x that for float texels).
      if ((texels + level.texels.size()) * 4 > std::numeric_limits<uint32_t>::max()) {
        throw std::length_error("scene textures exceed 2^30 texels");
      }
      out.level_offsets.push_back(static_cast<uint32_t>(texels));
      texels += level.texels.size();
      for (const glm::vec4& texel : level.texels) {
        if (format == TexelFormat::Rgba8) {
          out.texels8.push_back(encode_srgb8(texel));
        } else {
          out.texels32.insert(out.texels32.end(), {texel.r, texel.g, texel.b, texel.a});
        }
      }
    }
    out.faces.push_back(gpu);
  }
  out.neighbors = build_adjacency(scene);
  return out;
}

}  // namespace seamcl
