// Guard bands (McDonald and Burley 2011): every mip level of every face stored with a band of
// texels around it, filled at build time from the neighbouring faces at the same texel density,
// so that a lookup clamped to the band's outer edge reads the neighbours' content near the seam.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
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
// Reads the scene's stored chains (no face of it may be deferred).
TextureLevel guard_banded_level(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t face,
                                int level, int band);

// Where a band's texels come from: texel (i, j) of level `level` of face `face`, a face around
// the banded one (or that face itself, at a boundary). Level sizes are the scene's.
class BandTexels {
 public:
  virtual ~BandTexels() = default;
  virtual const glm::vec4& at(uint32_t face, size_t level, int i, int j) const = 0;
};

// The band of level `level` of `face` as guard_banded_level fills it, without the face's own
// texels: emit(si, sj, texel) for every band texel, (si, sj) its place in the banded level, row
// by row. The scene gives the sizes and the adjacency only (its faces may be deferred); every
// texel comes from `texels`. The same texels in give the same bits out, whatever holds them.
void for_each_band_texel(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t face, int level,
                         int band, const BandTexels& texels,
                         const std::function<void(int si, int sj, const glm::vec4& texel)>& emit);

// How far into each level of each face the bands of the scene read: depths[f][l] is the smallest
// k such that every texel of level l of face f that any band reads lies less than k texels from
// one of the level's edges (0: no band reads the level). From the sizes and the adjacency alone,
// so known for a deferred scene before any texel exists. With neighbours of the same texel
// density it is about `band`; anisotropic or coarse levels read deeper (up to the whole level).
std::vector<std::vector<int>> band_read_depths(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, int band);

// What the bands read of one face's chain: of each level, the texels less than depths[l] from one
// of its edges (the whole level where the strips meet). Packing holds these for the faces around
// the packing front instead of their whole chains: a 512x512 face's strips 4 deep are about 3%
// of its floats.
class EdgeStrips {
 public:
  EdgeStrips(const MipChain& chain, const std::vector<int>& depths);
  // Texel (i, j) of level `level`, as the chain held it; std::logic_error for one outside the
  // strips (a band reading deeper than band_read_depths said).
  const glm::vec4& at(size_t level, int i, int j) const;
  size_t texel_count() const { return texels_.size(); }

 private:
  struct Strips {
    int width = 0, height = 0;
    int depth = 0;  // the level whole when 2 depth >= a side
    size_t first = 0;  // in texels_
    bool whole() const { return 2 * depth >= width || 2 * depth >= height; }
  };
  std::vector<Strips> levels_;
  std::vector<glm::vec4> texels_;
};

}  // namespace seamcl
