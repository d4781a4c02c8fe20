#include <seamcl/pipeline/packed_cube.h>

#include <cassert>

namespace seamcl {

CubeBake cube_bake(CubeMethod method) {
  switch (method) {
    case CubeMethod::Stretch:
    case CubeMethod::Fixup: return CubeBake::Stretch;
    case CubeMethod::Warp: return CubeBake::Warp;
    default: return CubeBake::Centres;
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

std::vector<float> pack_cube_texels(const CubeMap& cube) {
  std::vector<float> out;
  out.reserve(cube.texel_count() * 4);
  for (const MipChain& face : cube.faces) {
    for (const TextureLevel& level : face.levels) {
      for (const glm::vec4& texel : level.texels) out.insert(out.end(), {texel.r, texel.g, texel.b, texel.a});
    }
  }
  assert(out.size() == cube.texel_count() * 4);
  return out;
}

}  // namespace seamcl
