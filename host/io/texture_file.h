// A face's texture as OpenImageIO reads it: the packed levels, decoded to linear float, written
// as one tiled, MIP-mapped float OpenEXR, so that OIIO's TextureSystem filters exactly the texels
// the kernels filter (the oracle tests and the lookup benchmark).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <seamcl/pipeline/packed_scene.h>

namespace seamcl {

// Level `level` of face `face` as the kernels read it: linear RGBA floats, row-major.
std::vector<float> packed_level_linear(const PackedScene& packed, uint32_t face, int level, int& width, int& height);

// Face `face`'s whole chain into a tiled (64x64) MIP-mapped float EXR at `path`. Throws
// std::runtime_error with OIIO's message on failure.
void write_face_mip_exr(const PackedScene& packed, uint32_t face, const std::string& path);

}  // namespace seamcl
