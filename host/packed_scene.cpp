#include "packed_scene.h"

#include <limits>
#include <stdexcept>

namespace seamcl {

PackedScene pack_scene(const Scene& scene) {
  PackedScene out;
  out.positions.reserve(scene.positions.size());
  for (const glm::vec3& p : scene.positions) out.positions.push_back({{p.x, p.y, p.z, 1.0f}});
  out.faces.reserve(scene.faces.size());
  out.texels.reserve(scene.texel_count());
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
      if (out.texels.size() + level.texels.size() > std::numeric_limits<uint32_t>::max()) {
        throw std::length_error("scene textures exceed 2^32 texels");
      }
      out.level_offsets.push_back(static_cast<uint32_t>(out.texels.size()));
      for (const glm::vec4& texel : level.texels) out.texels.push_back(encode_srgb8(texel));
    }
    out.faces.push_back(gpu);
  }
  return out;
}

}  // namespace seamcl
