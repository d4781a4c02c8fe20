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

#include <glm/glm.hpp>

#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {

// What ptex_filter.cl reads: per face its record, the texel offset of each of its resolutions,
// and the texels in the file's element type (1, 2 or 4 bytes), channels interleaved, followed by
// SEAMCL_PTEX_TEXEL_TAIL bytes that the kernel's vector reads may touch.
struct PtexFilterData {
  PtexFilterTexture texture{};
  std::vector<PtexFilterFace> faces;
  std::vector<cl_uint> level_offsets;
  std::vector<uint8_t> texels;
  int alpha_channel = -1;  // the file's alpha channel (-1: none), for showing the others as colour
};

// A render's Ptex filter (kernels/shade_resolve.cl's Ptex variant): the texture and the shading's
// settings (with texture.seams the render's seam rule).
struct PtexRenderTexture {
  const PtexFilterData* data = nullptr;
  PtexShading shading{};
};

// Which of the file's channels show as red, green and blue (-1: 0), as the .ptx scene reader maps
// them: the channels other than alpha; one is grey, two are red and green.
std::array<cl_int, 3> ptex_rgb_source(int channels, int alpha_channel);

// The albedo of a fragment at (u, v) of `face` with screen derivatives of uv, as the Ptex variant
// of the shading kernel computes it: the lookup (face, u, v, (|dudx| + |dudy|) * width_scale,
// (|dvdx| + |dvdy|) * width_scale) through ptex_filter_twin, its channels mapped by rgb_source;
// 0 for a non-finite point.
glm::vec3 ptex_albedo_twin(const PtexRenderTexture& ptex, int face, float u, float v, float dudx, float dvdx, float dudy,
                           float dvdy);
// The query ptex_albedo_twin makes (non-finite widths become a whole face: 1).
PtexFilterQuery ptex_fragment_query(const PtexShading& shading, int face, float u, float v, float dudx, float dvdx,
                                    float dudy, float dvdy);

// One lookup; channels beyond the texture's are 0. A query whose face is out of range gives zeros.
std::array<float, 4> ptex_filter_twin(const PtexFilterData& data, const PtexFilterQuery& query);
// The same on data's texels with another texture record (a render's, whose seams is its seam rule).
std::array<float, 4> ptex_filter_twin(const PtexFilterData& data, const PtexFilterTexture& texture,
                                      const PtexFilterQuery& query);

}  // namespace seamcl
