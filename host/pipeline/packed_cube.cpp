#include <seamcl/pipeline/packed_cube.h>

#include <algorithm>
#include <cassert>

#include "pipeline/stages/cube_sample_twin.h"

namespace seamcl {

CubeBake cube_bake(CubeMethod method) { return cube_preparation(method).bake; }

CubePreparation cube_preparation(CubeMethod method) {
  switch (method) {
    case CubeMethod::Stretch:
    case CubeMethod::Fixup:
    case CubeMethod::FixupLevel: return {CubeBake::Stretch, false, false};
    case CubeMethod::Warp: return {CubeBake::Warp, false, false};
    case CubeMethod::Fov: return {CubeBake::Fov, false, false};
    case CubeMethod::Average: return {CubeBake::Centres, true, false};
    case CubeMethod::Border: return {CubeBake::Centres, false, true};
    default: return {CubeBake::Centres, false, false};
  }
}

int cube_method_code(CubeMethod method) {
  switch (method) {
    case CubeMethod::Clamp: return SEAMCL_CUBE_CLAMP;
    case CubeMethod::Seamless: return SEAMCL_CUBE_SEAMLESS;
    case CubeMethod::Stretch: return SEAMCL_CUBE_STRETCH;
    case CubeMethod::Warp: return SEAMCL_CUBE_WARP;
    case CubeMethod::Fixup: return SEAMCL_CUBE_FIXUP;
    case CubeMethod::Discard: return SEAMCL_CUBE_DISCARD;
    case CubeMethod::Fov: return SEAMCL_CUBE_FOV;
    case CubeMethod::Average: return SEAMCL_CUBE_AVERAGE;
    case CubeMethod::FixupLevel: return SEAMCL_CUBE_FIXUP_LEVEL;
    case CubeMethod::Border: return SEAMCL_CUBE_BORDER;
  }
  return SEAMCL_CUBE_CLAMP;
}

CubeSampler cube_sampler(CubeMethod method, Filter filter, int max_aniso, int size) {
  CubeSampler s{};
  s.size = size;
  s.level_count = 0;
  for (int m = size; m >= 1; m /= 2) ++s.level_count;
  s.method = cube_method_code(method);
  s.filter = filter == Filter::Bilinear    ? SEAMCL_FILTER_BILINEAR
             : filter == Filter::Trilinear ? SEAMCL_FILTER_TRILINEAR
                                           : SEAMCL_FILTER_ANISO;
  s.max_aniso = max_aniso;
  return s;
}

std::vector<float> pack_cube_texels(const CubeMap& cube, bool border) {
  std::vector<float> plain;
  plain.reserve(cube.texel_count() * 4);
  for (const MipChain& face : cube.faces) {
    for (const TextureLevel& level : face.levels) {
      for (const glm::vec4& texel : level.texels) plain.insert(plain.end(), {texel.r, texel.g, texel.b, texel.a});
    }
  }
  assert(plain.size() == cube.texel_count() * 4);
  if (!border) return plain;
  const int n = cube.size;
  std::vector<float> out(cube_texel_count(n, true) * 4, 0.0f);
  auto texel = [&](uint32_t index) { return glm::vec4(plain[4 * index], plain[4 * index + 1], plain[4 * index + 2], plain[4 * index + 3]); };
  for (int f = 0; f < kCubeFaces; ++f) {
    for (int level = 0; level < cube.level_count(); ++level) {
      const int m = n >> level;
      for (int j = -1; j <= m; ++j) {
        for (int i = -1; i <= m; ++i) {
          const bool out_i = i < 0 || i >= m, out_j = j < 0 || j >= m;
          const int ci = std::clamp(i, 0, m - 1), cj = std::clamp(j, 0, m - 1);
          glm::vec4 value;
          // What cube-seamless's tap reads there (cube_sample.cl, cube_tap): the border is its
          // lookup stored, so a bordered bilinear tap needs no fold at run time.
          if (!out_i && !out_j) {
            value = texel(cube_texel_index(n, f, level, i, j));
          } else if (out_i && out_j) {
            value = (texel(cube_texel_index(n, f, level, ci, cj)) + texel(cube_fold_texel(n, f, level, m, i, cj)) +
                     texel(cube_fold_texel(n, f, level, m, ci, j))) *
                    (1.0f / 3.0f);
          } else {
            value = texel(cube_fold_texel(n, f, level, m, i, j));
          }
          const uint32_t at = cube_border_texel_index(n, f, level, i, j);
          for (int c = 0; c < 4; ++c) out[4 * size_t{at} + c] = value[c];
        }
      }
    }
  }
  return out;
}

CubeMap bake_cube_for(CubeMethod method, const DirectionFunction& radiance, int size, int samples) {
  const CubePreparation preparation = cube_preparation(method);
  CubeMap cube = bake_cube_map(radiance, size, preparation.bake, samples);
  if (preparation.average_edges) average_cube_edges(cube);
  return cube;
}

size_t cube_bytes(CubeMethod method, int size) {
  return cube_texel_count(size, cube_preparation(method).border) * 4 * sizeof(float);
}

}  // namespace seamcl
