// The scalar twin of kernels/texture_sample.cl: the sampler every seam
// method is a setting of (filter, address mode, renormalisation).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/pipeline/texture_view.h>

namespace seamcl {


// log2 within 5e-6 for x > 0, the polynomial the kernels use.
float approx_log2(float x);

FilterSum filter_texture_reference(const TextureView& textures, uint32_t face, const SamplerParams& sampler,
                                   int address, float u, float v, float dudx, float dvdx, float dudy, float dvdy);
// What a method sums before renormalising: filter_texture_reference on the face with the
// sampler's address mode and, for traverse, on each edge neighbour (border) through its uv
// transform.
FilterSum method_sum_reference(const TextureView& textures, uint32_t face, const SamplerParams& sampler, float u, float v,
                               float dudx, float dvdx, float dudy, float dvdy);
// The lookup as a seam method asks for it (renormalisation and zero-coverage rule included).
glm::vec4 sample_texture_reference(const TextureView& textures, uint32_t face, const SamplerParams& sampler, float u,
                                   float v, float dudx, float dvdx, float dudy, float dvdy);

}  // namespace seamcl
