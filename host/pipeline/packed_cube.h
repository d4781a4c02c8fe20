// A cube map as the kernels read it (kernels/cube_sample.cl): the texels of every face and level
// in one linear RGBA32F array, and the sampler settings of a cube method.
#pragma once
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/cube_map.h>

namespace seamcl {

// How the method's faces are baked: stretch for cube-stretch, cube-fixup and cube-fixup-level,
// warp for cube-warp, fov for cube-fov, texel centres for the others.
CubeBake cube_bake(CubeMethod method);
// What a method's cube goes through between the environment and the device: the bake, then
// CubeMapGen's edge averaging (cube-average), then packing with a one-texel border (cube-border).
struct CubePreparation {
  CubeBake bake = CubeBake::Centres;
  bool average_edges = false;
  bool border = false;
  bool operator==(const CubePreparation& o) const {
    return bake == o.bake && average_edges == o.average_edges && border == o.border;
  }
};
CubePreparation cube_preparation(CubeMethod method);
// SEAMCL_CUBE_* of the method.
int cube_method_code(CubeMethod method);
// The lookup settings: the cube's size and levels, the method and the render's filter (ewa,
// which the cube lookup does not implement, filters as aniso).
CubeSampler cube_sampler(CubeMethod method, Filter filter, int max_aniso, int size);

// Face-major, then level, then row (the layout CubeSampler's comment in seamcl_types.h states);
// with `border`, every level with its one-texel border of the texels a seamless tap one texel
// out reads (corners: the mean of the three corner texels), cube-border's layout.
std::vector<float> pack_cube_texels(const CubeMap& cube, bool border = false);

// The method's cube, baked (and averaged) as cube_preparation says.
CubeMap bake_cube_for(CubeMethod method, const DirectionFunction& radiance, int size, int samples);
// The device bytes of the method's packed cube (RGBA32F).
size_t cube_bytes(CubeMethod method, int size);

}  // namespace seamcl
