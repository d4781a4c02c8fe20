// The scalar twin of kernels/cube_sample.cl: a cube-map lookup by direction with its screen
// derivatives, for every seam method (SEAMCL_CUBE_*).
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/pipeline/texture_view.h>

namespace seamcl {

// A direction on the face it selects (ties to x, then y): uv in [0, 1] and d(uv)/d(pixel).
struct CubeUv {
  int face = 0;
  float s = 0.5f, t = 0.5f;
  float dsdx = 0, dtdx = 0, dsdy = 0, dtdy = 0;
  bool valid = false;  // false for a zero or non-finite direction (then face 0, its centre)
};
CubeUv cube_project(glm::vec3 d, glm::vec3 ddx, glm::vec3 ddy);

// First texel of (face, level) plus (i, j) in the cube's texel array (layout: CubeSampler).
uint32_t cube_texel_index(int size, int face, int level, int i, int j);
// cube-border's layout: texel (i, j), i, j in -1..m, of (face, level) stored with its border.
uint32_t cube_border_texel_index(int size, int face, int level, int i, int j);
// The per-level coordinate scale of fixup-level ((m - 1) / m) and fov ((m - 0.5) / m); 1 otherwise.
float cube_level_scale(int method, int m);
// The texel of the adjacent face a seamless tap (i, j) of an m x m level reaches, the tap being
// outside the face in exactly one axis and at most m texels out.
uint32_t cube_fold_texel(int size, int face, int level, int m, int i, int j);

// The fixup's coordinate scale at `lod` for level-0 size n: 1 - exp2(lod) / n.
float cube_fixup_scale(float lod, int size);
// The face uv the fixup samples at `lod` (before the lod clamp to the chain).
glm::vec2 cube_fixup_uv(float s, float t, float lod, int size);

// The filtered sum before discard's renormalisation (weight: that of the taps inside the face).
FilterSum cube_filter_reference(const std::vector<float>& texels, const CubeSampler& cube, const CubeUv& c,
                                float roughness, float explicit_lod, int method);
// The lookup's colour, as kernels/cube_sample.cl's sample_cube returns it.
glm::vec4 sample_cube_reference(const std::vector<float>& texels, const CubeSampler& cube, glm::vec3 d, glm::vec3 ddx,
                                glm::vec3 ddy, float roughness = 0.0f, float explicit_lod = -1.0f);

}  // namespace seamcl
