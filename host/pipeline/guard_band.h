// Guard bands (McDonald and Burley 2011): every mip level of every face stored with a band of
// texels around it, filled at build time from the neighbouring faces at the same level, so that
// a lookup clamped to the band's outer edge reads the neighbours' content near the seam.
#pragma once
#include <cstdint>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// Level `level` of face `face`, (w + 2 band) x (h + 2 band) texels, the face's own texels in the
// middle. A band texel holds the neighbour's level (the same index, or its last level if it has
// fewer) sampled bilinearly, clamped, at the band texel's centre carried across the edge by the
// adjacency transform. Corner texels go across one edge and then the next (the diagonal face at a
// valence-4 corner); without a neighbour the band repeats the nearest texel of what it reached.
TextureLevel guard_banded_level(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t face,
                                int level, int band);

}  // namespace seamcl
