// Cube maps: six n x n faces with full mip chains in the D3D/GL order and orientation (the
// major-axis table of the GL and Vulkan specs), and how a face is baked from a function of
// direction. The bakes are those of Castano's "Seamless Cube Map Filtering": texel centres
// (map_1), the linear stretch whose edge texels lie on the cube's edges (map_2), and the cubic
// warp of the centres (warp3).
#pragma once
#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/scene/scene.h>

namespace seamcl {

// +X, -X, +Y, -Y, +Z, -Z: the face index of the APIs.
inline constexpr int kCubeFaces = 6;

// A direction on the face it selects: the face, its coordinates sc, tc in [-1, 1] (the table's
// sc/|ma|, tc/|ma|) and uv = (sc + 1) / 2, (tc + 1) / 2 (texel (i, j) of an n x n level centred at
// ((i + .5) / n, (j + .5) / n), row 0 at t = 0, as in the face textures).
struct CubeCoords {
  int face = 0;
  float sc = 0, tc = 0;
};

// The major-axis table: the face of direction d and its coordinates. Ties between the largest
// components go to x, then y (|x| >= |y| and |x| >= |z| selects a +-X face; else |y| >= |z| a
// +-Y face): the specs leave ties to the implementation; this is the order the kernels use.
// A zero or non-finite direction gives face 0 at its centre.
CubeCoords cube_coords(glm::vec3 d);
// The point of face `face` at (sc, tc) (any values, also beyond the face): major component +-1.
glm::vec3 cube_direction(int face, float sc, float tc);

// Where a face texel's direction comes from.
enum class CubeBake {
  Centres,  // map_1(x) = (x + 0.5) * 2 / n - 1: the texel centre (cube-clamp, -seamless, -discard)
  Stretch,  // map_2(x) = 2 x / (n - 1) - 1: edge texels on the cube edge (cube-stretch, -fixup)
  Warp,     // warp3(map_1(x)), warp3(u) = u + a u^3, a = n^2 / (n - 1)^3 (cube-warp)
  Fov,      // map_1(x) n / (n - 0.5): the face rendered with the post's (Ysaneya's) FOV 2 atan(n / (n - 0.5))
            // (cube-fov). Its edge texel centres land at (n - 1) / (n - 0.5), a quarter of a tweaked
            // texel short of the edge, not on it: the FOV that puts them there is 2 atan(n / (n - 1)),
            // which is map_2, the stretch bake.
};
std::string to_string(CubeBake bake);

float cube_map1(float x, int n);
float cube_map2(float x, int n);// 0 (the face centre) for n = 1
float cube_warp_coefficient(int n);  // n^2 / (n - 1)^3; 0 for n = 1
float cube_warp3(float u, int n);
float cube_map_fov(float x, int n);  // map_1(x, n) * n / (n - 0.5)
// The face coordinate texel x of an n-texel level stands for under `bake`.
float cube_bake_coordinate(CubeBake bake, float x, int n);

// Six faces of level-0 size n (a power of two), each with a full chain down to 1 x 1. Every level
// is baked on its own from the environment at its own size (a stretch- or warp-baked level is
// not a box filter of the one above: its edge texels must lie on the cube edges at every level).
struct CubeMap {
  int size = 0;
  CubeBake bake = CubeBake::Centres;
  std::array<MipChain, kCubeFaces> faces;

  int level_count() const;
  size_t texel_count() const;  // all levels of all faces: 6 (4 n^2 - 1) / 3
};

// Bakes every level of every face: texel (i, j) of an m x m level is the mean of `radiance` over
// samples x samples points spread evenly over the texel in index space (i + (k + .5) / samples
// - .5), each taken through the bake's map; samples = 1 evaluates the texel's own direction.
// Stretch and warp edge texels always take their own direction (the edge's), so that both
// faces hold the same value there.
// Directions passed to `radiance` are unit vectors. Throws InputError("cube_size") unless n is a
// power of two in 1..kMaxCubeSize.
inline constexpr int kMaxCubeSize = 512;  // 6 (4 n^2 - 1) / 3 texels: 2^21 for 512
CubeMap bake_cube_map(const DirectionFunction& radiance, int size, CubeBake bake, int samples = 1);

// The texel across the edge: for texel (i, j) of an m x m level of `face` on the face's border,
// the texels of the adjacent faces that share its edge (one) or corner (two), each as
// (face, i, j). Empty for an interior texel; for m = 1 every face's texel meets every edge, and
// the other five faces are returned.
struct CubeTexel {
  int face, i, j;
  bool operator<(const CubeTexel& o) const {
    return face != o.face ? face < o.face : j != o.j ? j < o.j : i < o.i;
  }
};
std::vector<CubeTexel> cube_edge_partners(int face, int m, int i, int j);

// CubeMapGen's edge averaging, at every level: each border texel becomes the mean of itself and
// its partners (cube_edge_partners), summed in one order for all of them, so the texels either
// side of an edge hold the same value bit for bit and the three at a corner too. With clamp
// lookups this closes the zero-order seam at the edge and shifts the edge texels' content by up to
// half a texel (the average stands where each face's own texel centre is).
void average_cube_edges(CubeMap& cube);

// Texels of a cube of level-0 size n (a power of two) in the kernels' layout: 6 (4 n^2 - 1) / 3,
// and with a one-texel border at every level 6 ((4 n^2 - 1) / 3 + 8 n - 4 + 4 (log2 n + 1)).
size_t cube_texel_count(int size, bool border);

}  // namespace seamcl
