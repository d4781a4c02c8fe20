// Scalar twin of kernels/ptex_filter.cl: the Ptex library's separable filters (PtexFilter::eval on
// a quad-mesh texture: point, bilinear, box, gaussian, bicubic) with its choice of resolution, its
// splitting of the kernel at face edges into the rotated neighbours (read at the kernel's
// resolution), its corner rules (valence 4: the diagonal face; 5 and more: the kernel made
// symmetric and applied to every corner face; 2 and 3: dropped and renormalised) and its border
// modes. Subfaces (quads of split non-quad faces) are not handled: the texture builder refuses them.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {

// What ptex_filter.cl reads: per face its record, the texel offset of each of its resolutions,
// and the texels in the file's element type (1, 2 or 4 bytes), channels interleaved.
struct PtexFilterData {
  PtexFilterTexture texture{};
  std::vector<PtexFilterFace> faces;
  std::vector<cl_uint> level_offsets;
  std::vector<uint8_t> texels;
};

// One lookup; channels beyond the texture's are 0. A query whose face is out of range gives zeros.
std::array<float, 4> ptex_filter_twin(const PtexFilterData& data, const PtexFilterQuery& query);

}  // namespace seamcl
