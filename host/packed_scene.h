// A scene flattened into the arrays the kernels read (and the twins read too): positions, faces
// with their texture level tables, and every texel of every level in one RGBA8 sRGB buffer.
#pragma once
#include <cstdint>
#include <vector>

#include "gpu_types.h"
#include "scene.h"
#include "texture_sample.h"

namespace seamcl {

struct PackedScene {
  std::vector<cl_float4> positions;     // xyz, w = 1
  std::vector<FaceGpu> faces;
  std::vector<uint32_t> level_offsets;  // per face, per level: first texel in `texels`
  std::vector<uint32_t> texels;         // RGBA8, sRGB-encoded RGB

  int input_triangles() const { return static_cast<int>(faces.size() * 2); }
  TextureView textures() const { return {&faces, &level_offsets, &texels}; }
  size_t texture_bytes() const { return texels.size() * sizeof(uint32_t); }
};

PackedScene pack_scene(const Scene& scene);

}  // namespace seamcl
