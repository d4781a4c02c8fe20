// Guard bands (McDonald and Burley 2011): every mip level of every face stored with a band of
// texels around it, filled at build time from the neighbouring faces at the same texel density,
// so that a lookup clamped to the band's outer edge reads the neighbours' content near the seam.
#pragma once
#include <cstdint>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// Level `level` of face `face`, (w + 2 band) x (h + 2 band) texels, the face's own texels in the
// middle. A band texel stands for its square of the surface continued past the face's edges, as
// the adjacency unfolds it, and holds what the face found there holds over that square: the
// level of that face whose texels are as long as the square's sides, box-filtered over it (so a
// 1x1 face's band beside a 256x256 face holds that face's mean, not one of its texels); where
// that face is coarser even at level 0, its bilinear interpolation at the square's centre.
// Where the square lies:
//   past one edge: the face across it, the square clamped onto it (beyond its far edge, that edge
//     repeats); at a mesh boundary, this face's own edge texels repeat (clamp);
//   past a corner whose vertex has valence 4: the diagonal face;
//   past a corner of valence 5 or more: the mean over the faces that share only the vertex, each
//     taken in both orientations (none of them continues the face more than another);
//   past a corner of valence 3, or of a boundary vertex or an open ring: the mean of the two
//     edges' continuations (the face across each, clamped onto it, or this face at a boundary).
// Every case is a function of the surface, not of the order of any face's vertices.
TextureLevel guard_banded_level(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t face,
                                int level, int band);

}  // namespace seamcl
