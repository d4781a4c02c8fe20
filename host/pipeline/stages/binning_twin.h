// Scalar twin of kernels/binning.cl: which triangle slots each tile's list holds.
#pragma once
#include <cstdint>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {

// Whether any sample position of tile (tile_x, tile_y) can be inside the triangle: no edge
// function is negative over the whole tile (checked at the corner where it is largest).
bool tile_may_be_covered(const TriangleSetup& s, int tile_x, int tile_y);

// Per tile (row-major, tiles_x * tiles_y), the slots binned into it, ascending.
std::vector<std::vector<uint32_t>> bin_triangles_reference(const std::vector<TriangleSetup>& setups,
                                                           const FrameParams& frame);

}  // namespace seamcl
