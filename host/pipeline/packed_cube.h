// A cube map as the kernels read it (kernels/cube_sample.cl): the texels of every face and level
// in one linear RGBA32F array, and the sampler settings of a cube method.
#pragma once
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/cube_map.h>

namespace seamcl {

// How the method's faces are baked: stretch for cube-stretch and cube-fixup, warp for
// cube-warp, texel centres for the others.
CubeBake cube_bake(CubeMethod method);
// SEAMCL_CUBE_* of the method.
int cube_method_code(CubeMethod method);
// The lookup settings: the cube's size and levels, the method and the render's filter (ewa,
// which the cube lookup does not implement, filters as aniso).
CubeSampler cube_sampler(CubeMethod method, Filter filter, int max_aniso, int size);

// Face-major, then level, then row (the layout CubeSampler's comment in seamcl_types.h states).
std::vector<float> pack_cube_texels(const CubeMap& cube);

}  // namespace seamcl
