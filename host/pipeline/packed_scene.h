// A scene flattened into the arrays the kernels read (and the twins read too): positions, faces
// with their texture level tables, and every texel of every level in one RGBA8 sRGB buffer.
#pragma once
#include <cstdint>
#include <vector>

#include <seamcl/core/uninitialized_allocator.h>
#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/pipeline/texture_view.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

struct PackedScene {
  std::vector<cl_float4> positions;     // xyz, w = 1
  std::vector<FaceGpu> faces;
  std::vector<FaceNeighbors> neighbors;  // edge adjacency (traverse, guard bands, the seam mask); may be empty
  std::vector<uint32_t> level_offsets;  // per face, per level: first texel in `texels`; stored
                                        // level-major (level 0 of every face, then level 1, ...)
  TexelFormat format = TexelFormat::Rgba8;
  int guard_band = 0;                   // band texels stored around every level (guardband method)
  size_t band_texels = 0;               // of all stored texels, those in bands
  // The texels: pack_scene sizes them unwritten and writes every one, faces in parallel.
  UninitializedVector<uint32_t> texels8;  // RGBA8, sRGB-encoded RGB (format Rgba8)
  UninitializedVector<float> texels32;    // linear RGBA32F, 4 floats a texel (format Rgba32f)
  std::vector<ReflectiveFace> reflective_faces;  // of faces with roughness >= 0 (FaceGpu.reflective)

  int input_triangles() const { return static_cast<int>(faces.size() * 2); }
  TextureView textures() const { return {&faces, &neighbors, &level_offsets, format, &texels8, &texels32, guard_band}; }
  size_t texel_count() const { return format == TexelFormat::Rgba8 ? texels8.size() : texels32.size() / 4; }
  size_t texel_bytes() const { return format == TexelFormat::Rgba8 ? sizeof(uint32_t) : 4 * sizeof(float); }
  // All stored texels, bands included; padding_bytes() is the bands' share.
  size_t texture_bytes() const { return texels8.size() * sizeof(uint32_t) + texels32.size() * sizeof(float); }
  size_t padding_bytes() const { return band_texels * texel_bytes(); }
  size_t adjacency_bytes() const { return neighbors.size() * sizeof(FaceNeighbors); }
};

inline constexpr int kMaxGuardBand = 16;

// Fills FaceNeighbors' reach_min_side / reach_max_side (traverse's per-edge early-out) from the
// sizes of the faces across each edge and past its ends, as they lie in the face's own uv (see
// seamcl_types.h); pack_scene calls it, and the Renderer when it adds the adjacency later. An edge
// with no such face, or one of a size below 1, keeps SEAMCL_SIDE_NONE (never skips).
void fill_edge_reach(const std::vector<FaceGpu>& faces, std::vector<FaceNeighbors>& neighbors);

// With guard_band > 0 every level is stored with that many band texels each side (guard_band.h).
// Faces are packed in parallel. A deferred face's chain (Scene::texture_source) is made while
// it is packed and dropped right after (with guard bands, only the strips along its edges that
// its neighbours' bands read are kept while those are packed), so that packing never holds the
// float copy of every texture: the packed texels are what stays.
PackedScene pack_scene(const Scene& scene, TexelFormat format = TexelFormat::Rgba8, int guard_band = 0);
// The same with the adjacency given: build_adjacency(scene), or empty for a packing without one
// (the Renderer's for methods that never read it; a guard band needs it: std::logic_error).
PackedScene pack_scene(const Scene& scene, TexelFormat format, int guard_band, std::vector<FaceNeighbors> adjacency);

}  // namespace seamcl
