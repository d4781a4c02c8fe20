#include <seamcl/pipeline/packed_scene.h>

#include <seamcl/pipeline/render_memory.h>

#include "core/srgb.h"
#include "pipeline/adjacency.h"
#include "pipeline/guard_band.h"
#include "pipeline/reflective_face.h"

#include <limits>
#include <stdexcept>

namespace seamcl {

PackedScene pack_scene(const Scene& scene, TexelFormat format, int guard_band) {
  if (guard_band < 0 || guard_band > kMaxGuardBand) throw std::invalid_argument("guard band out of range");
  PackedScene out;
  out.format = format;
  out.guard_band = guard_band;
  out.neighbors = build_adjacency(scene);
  out.positions.reserve(scene.positions.size());
  for (const glm::vec3& p : scene.positions) out.positions.push_back({{p.x, p.y, p.z, 1.0f}});
  out.faces.reserve(scene.faces.size());
  // Exactly what is stored, bands included: growing by push_back would hold up to 3x meanwhile.
  const size_t stored_texels = packed_texture_memory(scene_sizes(scene), format, guard_band).texels;
  if (stored_texels > std::numeric_limits<uint32_t>::max() / 4) throw std::length_error("scene textures exceed 2^30 texels");
  if (format == TexelFormat::Rgba8) {
    out.texels8.reserve(stored_texels);
  } else {
    out.texels32.reserve(stored_texels * 4);
  }
  size_t texels = 0;
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const Face& face = scene.faces[f];
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
    gpu.reflective = face.roughness >= 0.0f ? static_cast<cl_int>(out.reflective_faces.size()) : -1;
    if (face.roughness >= 0.0f) out.reflective_faces.push_back(reflective_face(scene, face));
    for (size_t l = 0; l < face.texture.levels.size(); ++l) {
      const TextureLevel banded = guard_band > 0 ? guard_banded_level(scene, out.neighbors, static_cast<uint32_t>(f),
                                                                      static_cast<int>(l), guard_band)
                                                 : TextureLevel{};
      const TextureLevel& level = guard_band > 0 ? banded : face.texture.levels[l];
      // Offsets are 32-bit texel indices (and 4x that for float texels).
      if ((texels + level.texels.size()) * 4 > std::numeric_limits<uint32_t>::max()) {
        throw std::length_error("scene textures exceed 2^30 texels");
      }
      out.level_offsets.push_back(static_cast<uint32_t>(texels));
      texels += level.texels.size();
      out.band_texels += level.texels.size() - face.texture.levels[l].texels.size();
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
  return out;
}

}  // namespace seamcl
